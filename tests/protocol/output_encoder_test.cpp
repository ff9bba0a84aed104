// The output encoding registry (daemon/output_encoder.hpp): every entry builds an encoder of its
// own name, an encoding without options refuses any with an OptionError naming the key, and
// hands out one shared encoder (so the publisher encodes each pose once for all its outputs).
#include "posefair/daemon/output_encoder.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace posefair::daemon {
namespace {

TEST(OutputEncoderRegistry, EveryEntryBuildsAnEncoderOfItsName) {
  ASSERT_FALSE(output_encoder_entries().empty());
  for (const OutputEncoderEntry* e : output_encoder_entries()) {
    SCOPED_TRACE(std::string(e->name));
    EXPECT_FALSE(e->description.empty());
    EXPECT_EQ(find_output_encoder(e->name), e);
    for (const posefair::OptionSpec& o : e->options) {
      EXPECT_FALSE(o.name.empty());
      EXPECT_FALSE(o.doc.empty());
    }
    const auto encoder = e->make({}, {});
    ASSERT_NE(encoder, nullptr);
    EXPECT_EQ(encoder->name(), e->name);
  }
  EXPECT_EQ(find_output_encoder("no-such-encoding"), nullptr);
}

TEST(OutputEncoderRegistry, BinaryIsTheDefaultAndTheClientEncodingsAreRegistered) {
  std::vector<std::string_view> expected{"binary", "json", "opentrack", "freed", "vmc", "vrchat"};
#ifdef POSEFAIR_WITH_DDS  // the build found Cyclone DDS (daemon/CMakeLists.txt)
  expected.push_back("dds");
#endif
  EXPECT_EQ(output_encoder_names(), expected);
  EXPECT_EQ(default_output_encoder()->name(), "binary");
}

TEST(OutputEncoderRegistry, AnEncodingWithoutOptionsRefusesAnyNamingTheKey) {
  for (const OutputEncoderEntry* e : output_encoder_entries()) {
    if (!e->options.empty()) continue;
    SCOPED_TRACE(std::string(e->name));
    const posefair::OptionMap given{{"zoom", std::int64_t{2}}};
    try {
      (void)e->make(given, {});
      ADD_FAILURE() << "an undeclared option was accepted";
    } catch (const posefair::OptionError& error) {
      EXPECT_EQ(error.key(), "zoom");
    }
  }
}

TEST(OutputEncoderRegistry, AnEncodingWithoutOptionsSharesOneEncoder) {
  for (const OutputEncoderEntry* e : output_encoder_entries()) {
    if (!e->options.empty()) continue;
    SCOPED_TRACE(std::string(e->name));
    EXPECT_EQ(e->make({}, {}), e->make({}, {}));
  }
}

}  // namespace
}  // namespace posefair::daemon
