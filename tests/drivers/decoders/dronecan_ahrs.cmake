# The DroneCAN uavcan.equipment.ahrs.Solution decoder (and float16).
posefair_add_test(dronecan_ahrs_decoder_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/dronecan_ahrs_decoder_test.cpp LIBS posefair::drivers LABELS drivers)
