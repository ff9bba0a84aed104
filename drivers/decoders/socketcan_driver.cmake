# The SocketCAN driver (socketcan_driver.hpp): a raw CAN socket on a named interface feeding a
# CAN decoder (can.cmake). Needs the kernel's linux/can.h headers (linux-libc-dev), nothing else.
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/socketcan_driver.cpp)
