# The hidraw driver's host-testable parts (included from tests/drivers/CMakeLists.txt).
#
# hidraw_tests: the sysfs uevent parser, finding nodes by HID id in a fake sysfs tree, refused
# options, waiting for an absent device. The driver against a real (uhid) device is
# tests/hw/hidraw_tests.cpp, inside the VM.
posefair_add_test(hidraw_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/hidraw_tests.cpp
  LIBS posefair::drivers
  LABELS "drivers;threads")
