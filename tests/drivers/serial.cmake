# The serial transport (included from tests/drivers/CMakeLists.txt).
#
# time_base_tests.cpp: the time rule for live devices (time_base.hpp), on simulated clocks; in
# drivers_tests (CMakeLists.txt here).
target_sources(drivers_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/time_base_tests.cpp)

# serial_tests: SerialPort and SerialDriver on pseudo-terminals (the driver opens the slave
# through a symlink, as through /dev/serial/by-id), with a line-protocol decoder defined in
# the test: samples, receive times and counters, chunked writes, prompt stops, unplug and
# replug (the master closed, the link re-pointed to a new pty), a device that appears late.
posefair_add_test(serial_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/serial_tests.cpp
  LIBS posefair::drivers
  LABELS "drivers;threads")
