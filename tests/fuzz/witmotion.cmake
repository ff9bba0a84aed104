# WitMotion decoder, seeded with frame streams (tests/fuzz/corpus/witmotion/).
posefair_add_fuzz_target(witmotion SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/witmotion_fuzz.cpp LIBS posefair::drivers)
