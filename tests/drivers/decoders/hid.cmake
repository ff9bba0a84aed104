# The HID report descriptor parser, the HID Sensor orientation and vendor layout decoders, and
# the GPIO edge pairing rule (drivers/decoders/hid.cmake).
posefair_add_test(hid_descriptor_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_report_descriptor_test.cpp
                  LIBS posefair::drivers LABELS drivers)
posefair_add_test(hid_decoder_tests
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_sensor_orientation_decoder_test.cpp
          ${CMAKE_CURRENT_SOURCE_DIR}/decoders/hid_vendor_layout_decoder_test.cpp
  LIBS posefair::drivers LABELS drivers)
posefair_add_test(gpio_edge_pairing_tests SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/decoders/gpio_edge_pairing_test.cpp
                  LIBS posefair::drivers LABELS drivers)
