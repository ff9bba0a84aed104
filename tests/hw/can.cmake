# socketcan_tests: the SocketCAN driver against the kernel's CAN stack on vcan interfaces it
# creates (root, modules vcan and can-raw): kernel filters, CAN FD, receive timestamps, error
# frames, interface down/up and delete/re-add; and the real posefaird fed by cansend,
# canplayer (can-utils) and python3-can, its poses collected over UDP.
posefair_add_test(socketcan_tests
  SOURCES socketcan_tests.cpp
  LIBS posefair::protocol posefair::drivers
  LABELS "hw;can")
add_dependencies(socketcan_tests posefaird)
