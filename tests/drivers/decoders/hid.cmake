# The HID report descriptor parser, the HID Sensor orientation and vendor layout decoders, and
# the GPIO edge pairing rule (drivers/decoders/hid.cmake).
target_sources(drivers_tests PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_report_descriptor_test.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_sensor_orientation_decoder_test.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_vendor_layout_decoder_test.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/decoders/gpio_edge_pairing_test.cpp)
