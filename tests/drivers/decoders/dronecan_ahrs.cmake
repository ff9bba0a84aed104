# The DroneCAN uavcan.equipment.ahrs.Solution decoder (and float16).
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/dronecan_ahrs_decoder_test.cpp)
