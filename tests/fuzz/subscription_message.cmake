# The subscription port's request parser and its handler (docs/protocol.md, "Subscribing"),
# seeded with the specification's golden requests (tests/fuzz/corpus/subscription_message/).
posefair_add_fuzz_target(subscription_message SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/subscription_message_fuzz.cpp
                         LIBS posefair::protocol)
