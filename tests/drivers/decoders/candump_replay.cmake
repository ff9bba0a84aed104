# candump logs replayed through the CAN decoders (the log format's own tests: tests/formats/).
posefair_add_test(candump_replay_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/candump_replay_test.cpp LIBS posefair::drivers LABELS drivers)
