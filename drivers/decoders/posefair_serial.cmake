# posefair's serial protocol for microcontroller trackers ($PFQ sentence and binary frame):
# decoder and encoders.
target_sources(posefair_drivers PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/posefair_serial_decoder.cpp)
