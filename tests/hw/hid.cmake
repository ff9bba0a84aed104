# hidraw_tests: the hidraw driver end to end inside the VM: uhid devices (the genuine ST HID
# Sensor orientation descriptor; a vendor report) read by the real posefaird through
# /dev/hidrawN found by USB id, poses checked at a UDP collector; destroy and create again.
posefair_add_test(hidraw_hw_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/hidraw_tests.cpp
  LIBS posefair::protocol posefair::drivers
  LABELS "hw;hid")
add_dependencies(hidraw_hw_tests posefaird)
