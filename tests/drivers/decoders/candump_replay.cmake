# candump logs replayed through the CAN decoders (the log format's own tests: tests/formats/).
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/decoders/candump_replay_test.cpp)
