# CAN decoders (can_decoder.hpp): the registry, posefair's own CAN layout, Xsens MTi CAN
# output, DroneCAN ahrs.Solution, with their frame encoders; the replay of candump logs
# (parsed by formats/candump_log) through the decoders. Pure code: no kernel CAN headers needed.
target_sources(posefair_drivers PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/can_decoder_registry.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/posefair_can_decoder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/xsens_can_decoder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/dronecan_ahrs_decoder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/candump_replay.cpp)
