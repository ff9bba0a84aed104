# The hidraw driver (hidraw_driver.hpp): USB/Bluetooth HID trackers through /dev/hidrawN, found
# by path or by HID id in sysfs, decoded by the HID decoders (hid.cmake). Linux only
# (linux/hidraw.h from the kernel headers, linux-libc-dev on Debian).
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/hidraw_driver.cpp)
