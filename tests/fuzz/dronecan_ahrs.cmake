# The DroneCAN ahrs.Solution decoder, seeded with valid transfers (tests/fuzz/corpus/dronecan_ahrs/).
posefair_add_fuzz_target(dronecan_ahrs SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/dronecan_ahrs_fuzz.cpp LIBS posefair::drivers)
