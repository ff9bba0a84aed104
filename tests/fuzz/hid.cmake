# The HID report descriptor parser (seeded with the HID 1.11 boot descriptors, the genuine ST
# orientation descriptor and built sensor descriptors), the HID Sensor orientation decoder and
# the vendor layout decoder (seeded with encoded reports); tests/fuzz/corpus/hid_*/.
posefair_add_fuzz_target(hid_descriptor SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/hid_descriptor_fuzz.cpp LIBS posefair::drivers)
posefair_add_fuzz_target(hid_sensor SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/hid_sensor_fuzz.cpp LIBS posefair::drivers)
posefair_add_fuzz_target(hid_vendor SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/hid_vendor_fuzz.cpp LIBS posefair::drivers)
