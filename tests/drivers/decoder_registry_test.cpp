// The decoder registry and the promises every decoder makes (decoder.hpp), checked the same way
// for each registered protocol: the names, feeding any split of a stream gives the same samples
// and counters, reset() forgets a partial frame, and random bytes neither crash a decoder nor
// yield anything but finite unit quaternions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"

namespace posefair::drivers {
namespace {

struct Collect final : DecodedSink {
  std::vector<DecodedSample> samples;
  void on_sample(const DecodedSample& s) override { samples.push_back(s); }
};

TEST(DecoderRegistry, EveryProtocolOfTheIssueIsRegisteredUnderItsName) {
  const std::vector<std::string> expected = {"bno08x-rvc", "posefair", "vectornav", "witmotion", "xsens", "yost"};
  // The registry's own list (sorted, one name each) holds every one of them; a new protocol
  // changes no line here.
  const std::vector<std::string> names = decoder_protocols();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end());
  EXPECT_EQ(names.size(), decoder_entries().size());
  for (const std::string& name : expected)
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  for (const std::string& name : names) {
    const auto d = make_decoder(name);
    ASSERT_NE(d, nullptr) << name;
    EXPECT_EQ(d->protocol(), name);
    EXPECT_EQ(d->counters(), DecoderCounters{}) << name;
  }
  EXPECT_EQ(make_decoder("nmea"), nullptr);
  EXPECT_EQ(make_decoder(""), nullptr);
}

// Every protocol of the three registries declares each key once, with a line of doc; an
// undeclared key or a value of the wrong type is refused as an OptionError that names the key.
template <class Entry, class Make>
void check_declared_options(std::span<const Entry* const> entries, Make make) {
  for (const Entry* e : entries) {
    SCOPED_TRACE(std::string(e->name));
    EXPECT_FALSE(e->description.empty());
    for (std::size_t i = 0; i < e->options.size(); ++i) {
      EXPECT_FALSE(e->options[i].doc.empty()) << e->options[i].name;
      for (std::size_t j = 0; j < i; ++j) EXPECT_NE(e->options[i].name, e->options[j].name);
    }
    try {
      make(*e, OptionMap{{"no_such_option", std::string("x")}});
      ADD_FAILURE() << "an undeclared key was accepted";
    } catch (const OptionError& err) {
      EXPECT_EQ(err.key(), "no_such_option");
    }
    for (const OptionSpec& o : e->options) {
      try {
        make(*e, OptionMap{{std::string(o.name), o.type == OptionType::Boolean ? OptionValue{std::string("x")} : OptionValue{true}}});
        ADD_FAILURE() << o.name << ": a value of the wrong type was accepted";
      } catch (const OptionError& err) {
        EXPECT_EQ(err.key(), o.name);
      }
    }
  }
}

TEST(DecoderRegistry, EveryKindDeclaresItsOptions) {
  check_declared_options(decoder_entries(), [](const DecoderEntry& e, const OptionMap& o) { (void)e.make(o); });
  check_declared_options(can_decoder_entries(), [](const CanDecoderEntry& e, const OptionMap& o) { (void)e.make(o); });
  check_declared_options(hid_decoder_entries(), [](const HidDecoderEntry& e, const OptionMap& o) { (void)e.configure(o); });
  for (const DecoderEntry* e : decoder_entries()) EXPECT_NE(e->make({}), nullptr) << e->name;  // the defaults work
  for (const CanDecoderEntry* e : can_decoder_entries()) EXPECT_NE(e->make({}), nullptr) << e->name;
  EXPECT_EQ(can_decoder_protocols().size(), can_decoder_entries().size());
  EXPECT_EQ(hid_decoder_protocols().size(), hid_decoder_entries().size());
}

// Random bytes with frame-start bytes of every protocol sprinkled in ('$', 0x55, 0xAA 0xAA,
// 0xFA 0xFF, 0xF5 0x50), so each decoder spends time in its partial-frame paths.
std::vector<std::uint8_t> noisy_bytes(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v) b = static_cast<std::uint8_t>(rng());
  const std::uint8_t starts[][2] = {{'$', 'V'}, {0x55, 0x59}, {0xAA, 0xAA}, {0xFA, 0xFF}, {0xF5, 0x50}};
  for (std::size_t i = 0; i + 1 < n; i += 1 + rng() % 40) {
    const auto& s = starts[rng() % 5];
    v[i] = s[0];
    v[i + 1] = s[1];
  }
  return v;
}

TEST(DecoderRegistry, AnySplitOfAStreamGivesTheSameSamplesAndCountersForEveryDecoder) {
  const std::vector<std::uint8_t> bytes = noisy_bytes(200000, 7);
  for (const std::string& name : decoder_protocols()) {
    SCOPED_TRACE(name);
    auto whole = make_decoder(name);
    Collect a;
    whole->feed(bytes, a);
    std::mt19937_64 rng(11);
    for (int round = 0; round < 5; ++round) {
      auto split = make_decoder(name);
      Collect b;
      for (std::size_t i = 0; i < bytes.size();) {
        const std::size_t n = std::min<std::size_t>(bytes.size() - i, 1 + rng() % (round == 0 ? 1 : 300));
        split->feed(std::span<const std::uint8_t>(bytes.data() + i, n), b);
        i += n;
      }
      ASSERT_EQ(a.samples.size(), b.samples.size());
      for (std::size_t k = 0; k < a.samples.size(); ++k) {
        ASSERT_EQ(a.samples[k].orientation.coeffs(), b.samples[k].orientation.coeffs()) << k;
        ASSERT_EQ(a.samples[k].flags, b.samples[k].flags) << k;
      }
      EXPECT_EQ(whole->counters(), split->counters());
    }
    EXPECT_EQ(whole->counters().bytes, bytes.size());
    for (const DecodedSample& s : a.samples) {
      ASSERT_TRUE(s.orientation.coeffs().allFinite());
      ASSERT_NEAR(s.orientation.norm(), 1.0, 1e-3);
    }
  }
}

TEST(DecoderRegistry, ResetForgetsAPartialFrame) {
  const std::vector<std::uint8_t> bytes = noisy_bytes(50000, 3);
  for (const std::string& name : decoder_protocols()) {
    SCOPED_TRACE(name);
    // A decoder that saw half a stream, then reset(), behaves like a fresh one on the rest.
    auto used = make_decoder(name);
    auto fresh = make_decoder(name);
    Collect ignored, a, b;
    used->feed(std::span<const std::uint8_t>(bytes.data(), bytes.size() / 2), ignored);
    used->reset();
    const std::span<const std::uint8_t> rest(bytes.data() + bytes.size() / 2, bytes.size() - bytes.size() / 2);
    used->feed(rest, a);
    fresh->feed(rest, b);
    ASSERT_EQ(a.samples.size(), b.samples.size());
  }
}

}  // namespace
}  // namespace posefair::drivers
