# daemon_can_e2e_tests: a candump log, written by the test with the CAN frame encoders (three
# protocols on two interfaces, with malformed lines), replayed through the real posefaird
# (type = "replay", candump = ...) to a UDP collector on 127.0.0.1. The live SocketCAN driver
# is tested against the kernel in tests/hw/socketcan_tests.cpp.
posefair_add_test(daemon_can_e2e_tests
  SOURCES daemon_can_e2e_tests.cpp
  LIBS posefair::protocol posefair::drivers
  LABELS "daemon;network;e2e;can;threads")
add_dependencies(daemon_can_e2e_tests posefaird)
