// Doubles as text: the fallback for libraries without floating-point std::to_chars (GCC 10's,
// Debian 11; GCC 9's, Noetic) writes the bytes std::to_chars writes and reads numbers back
// exactly, so that a table file or a learning curve reads the same whichever compiler made it.
#include "cartpole_qlearning/io/number_text.h"

#include <gtest/gtest.h>

#include <clocale>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace cartpole_qlearning;

namespace
{
std::string fallbackShortest(double value)
{
  char text[64];
  const std::to_chars_result written = number_text_fallback::writeShortest(text, text + sizeof text, value);
  EXPECT_EQ(written.ec, std::errc());
  return std::string(text, written.ptr);
}

std::string fallbackGeneral(double value, int precision)
{
  char text[64];
  const std::to_chars_result written = number_text_fallback::writeGeneral(text, text + sizeof text, value, precision);
  EXPECT_EQ(written.ec, std::errc());
  return std::string(text, written.ptr);
}

bool sameBits(double a, double b)
{
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// A million random bit patterns (every exponent, subnormals, both signs) and the edge cases; a
// tenth of them in the ASan build (tools/sanitize.sh), where the million take a minute of CI's
// time and the plain build's run already holds every one of them to std::to_chars.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t kRandomValues = 100000;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr std::size_t kRandomValues = 100000;
#else
constexpr std::size_t kRandomValues = 1000000;
#endif
#else
constexpr std::size_t kRandomValues = 1000000;
#endif

std::vector<double> values()
{
  std::vector<double> all;
  std::mt19937_64 bits(42);  // mt19937_64's sequence is fixed by the standard
  while (all.size() < kRandomValues)
  {
    const std::uint64_t pattern = bits();
    double value = 0.0;
    std::memcpy(&value, &pattern, sizeof value);
    if (std::isfinite(value))
      all.push_back(value);
  }
  const double edges[] = {0.0,
                          2.4,
                          0.1,
                          0.3,
                          1.0 / 3.0,
                          100.0,
                          475.0,
                          1e15,
                          1e16,
                          1e17,
                          1e21,
                          1e22,
                          1e23,
                          123456789012345680000.0,
                          9007199254740993.0,
                          std::numeric_limits<double>::denorm_min(),
                          std::numeric_limits<double>::min(),
                          std::nextafter(std::numeric_limits<double>::min(), 0.0),
                          std::numeric_limits<double>::max(),
                          std::numeric_limits<double>::epsilon()};
  for (double value : edges)
    all.push_back(value);
  for (int exponent = -1074; exponent <= 1023; ++exponent)  // powers of two and their neighbours
  {
    const double power = std::ldexp(1.0, exponent);
    all.push_back(power);
    all.push_back(std::nextafter(power, 0.0));
    all.push_back(std::nextafter(power, std::numeric_limits<double>::infinity()));
  }
  for (int whole = 0; whole <= 20000; ++whole)
    all.push_back(whole);
  // The random patterns have both signs already; the others get theirs.
  const std::size_t chosen = all.size();
  for (std::size_t i = kRandomValues; i < chosen; ++i)
    all.push_back(-all[i]);
  return all;
}
}  // namespace

// The bytes C++17's std::to_chars writes (GCC 11's libstdc++), fixed here so that a library
// without it (GCC 10) is held to them too.
TEST(NumberTextTest, TheFallbackWritesTheStandardLibrarysKnownBytes)
{
  const std::vector<std::pair<double, std::string>> known = {
      {2.4, "2.4"},
      {0.1, "0.1"},
      {100.0, "100"},
      {475.0, "475"},
      {0.0, "0"},
      {-0.0, "-0"},
      {-1.5, "-1.5"},
      {1e22, "1e+22"},
      {1e-7, "1e-07"},
      {0.001, "0.001"},
      {123456.789, "123456.789"},
      {1.0 / 3.0, "0.3333333333333333"},
      {123456789012345680000.0, "123456789012345683968"},  // fixed, the double's own digits
      {1e100, "1e+100"},
      {std::numeric_limits<double>::denorm_min(), "5e-324"},
      {std::numeric_limits<double>::max(), "1.7976931348623157e+308"},
      {std::numeric_limits<double>::infinity(), "inf"},
      {-std::numeric_limits<double>::infinity(), "-inf"},
  };
  for (const auto& [value, text] : known)
  {
    EXPECT_EQ(fallbackShortest(value), text);
    EXPECT_EQ(shortestText(value), text);
  }
  EXPECT_EQ(fallbackGeneral(2.4, 17), "2.3999999999999999");
  EXPECT_EQ(fallbackGeneral(2.4, 15), "2.4");
  EXPECT_EQ(fallbackGeneral(1e-5, 15), "1e-05");
  EXPECT_EQ(fallbackGeneral(1e-5, 17), "1.0000000000000001e-05");
  EXPECT_EQ(fallbackGeneral(1e20, 15), "1e+20");
}

TEST(NumberTextTest, TheFallbackWritesWhatStdToCharsWritesAndReadsItBackExactly)
{
  std::size_t compared = 0;
  std::size_t shortest_differences = 0;
  std::size_t general_differences = 0;
  std::size_t read_failures = 0;
  for (double value : values())
  {
    const std::string text = fallbackShortest(value);
    double back = 0.0;
    const std::from_chars_result read = number_text_fallback::readDouble(text.data(), text.data() + text.size(), back);
    if (read.ec != std::errc() || read.ptr != text.data() + text.size() || !sameBits(back, value))
    {
      if (++read_failures <= 5)
        ADD_FAILURE() << text << " does not read back as " << std::hexfloat << value;
    }
#if defined(__cpp_lib_to_chars)
    char standard[64];
    const std::to_chars_result written = std::to_chars(standard, standard + sizeof standard, value);
    if (std::string(standard, written.ptr) != text && ++shortest_differences <= 5)
      ADD_FAILURE() << std::hexfloat << value << ": std::to_chars " << std::string(standard, written.ptr)
                    << ", the fallback " << text;
    // The table file's form: printf's %.15g to %.17g.
    for (int precision = 15; precision <= 17; precision += 2)
    {
      const std::to_chars_result general =
          std::to_chars(standard, standard + sizeof standard, value, std::chars_format::general, precision);
      const std::string fallback = fallbackGeneral(value, precision);
      if (std::string(standard, general.ptr) != fallback && ++general_differences <= 5)
        ADD_FAILURE() << std::hexfloat << value << " at precision " << precision << ": std::to_chars "
                      << std::string(standard, general.ptr) << ", the fallback " << fallback;
    }
    double standard_back = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), standard_back);
    if (!sameBits(standard_back, back) && ++read_failures <= 5)
      ADD_FAILURE() << text << ": std::from_chars and the fallback read different values";
#endif
    ++compared;
  }
  EXPECT_EQ(shortest_differences, 0u);
  EXPECT_EQ(general_differences, 0u);
  EXPECT_EQ(read_failures, 0u);
  EXPECT_GE(compared, kRandomValues);
#if !defined(__cpp_lib_to_chars)
  std::cout << "[ NOTE     ] this standard library has no floating-point std::to_chars (GCC < 11): the "
               "fallback is held to the known bytes, and to reading back exactly the "
            << compared << " values\n";
#endif
}

// from_chars' rules, not strtod's: no leading space, no '+', no hexadecimal; an exponent without
// digits is not read; out of range leaves the value alone.
TEST(NumberTextTest, TheFallbackReadsWhatStdFromCharsReads)
{
  struct Case
  {
    std::string text;
    std::size_t length;  // characters read
    std::errc ec;
    double value;  // 7 when untouched
  };
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Case> cases = {
      {"2.4", 3, std::errc(), 2.4},
      {"-0", 2, std::errc(), -0.0},
      {"1.5e3x", 5, std::errc(), 1500.0},
      {".5", 2, std::errc(), 0.5},
      {"5.", 2, std::errc(), 5.0},
      {"1e", 1, std::errc(), 1.0},
      {"1e+", 1, std::errc(), 1.0},
      {"0x10", 1, std::errc(), 0.0},
      {"4e-320", 6, std::errc(), 4e-320},
      {"-Infinity", 9, std::errc(), -inf},
      {"infin", 3, std::errc(), inf},
      {"+1", 0, std::errc::invalid_argument, 7.0},
      {" 1", 0, std::errc::invalid_argument, 7.0},
      {"-", 0, std::errc::invalid_argument, 7.0},
      {".", 0, std::errc::invalid_argument, 7.0},
      {"1e400", 5, std::errc::result_out_of_range, 7.0},
      {"1e-400", 6, std::errc::result_out_of_range, 7.0},
  };
  for (const Case& c : cases)
  {
    double value = 7.0;
    const std::from_chars_result read =
        number_text_fallback::readDouble(c.text.data(), c.text.data() + c.text.size(), value);
    EXPECT_EQ(read.ptr - c.text.data(), static_cast<std::ptrdiff_t>(c.length)) << c.text;
    EXPECT_EQ(read.ec, c.ec) << c.text;
    EXPECT_TRUE(sameBits(value, c.value)) << c.text << " read as " << value;
#if defined(__cpp_lib_to_chars)
    double standard = 7.0;
    const std::from_chars_result expected = std::from_chars(c.text.data(), c.text.data() + c.text.size(), standard);
    EXPECT_EQ(read.ptr, expected.ptr) << c.text;
    EXPECT_EQ(read.ec, expected.ec) << c.text;
    EXPECT_TRUE(sameBits(value, standard)) << c.text;
#endif
  }
  double nan = 0.0;
  const std::string text = "nan(abc)";
  EXPECT_EQ(number_text_fallback::readDouble(text.data(), text.data() + text.size(), nan).ptr, text.data() + 8);
  EXPECT_TRUE(std::isnan(nan));
}

// A user's locale with a decimal comma changes neither the text nor its reading.
TEST(NumberTextTest, TheLocaleChangesNothing)
{
  const char* previous = std::setlocale(LC_NUMERIC, nullptr);
  const std::string saved = previous ? previous : "C";
  bool comma = false;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"})
  {
    if (std::setlocale(LC_NUMERIC, name) != nullptr)
    {
      comma = true;
      break;
    }
  }
  if (!comma)
    GTEST_SKIP() << "no locale with a decimal comma is installed here";
  EXPECT_EQ(fallbackShortest(2.4), "2.4");
  EXPECT_EQ(fallbackGeneral(2.4, 17), "2.3999999999999999");
  double value = 0.0;
  const std::string text = "2.5";
  number_text_fallback::readDouble(text.data(), text.data() + text.size(), value);
  EXPECT_EQ(value, 2.5);
  std::setlocale(LC_NUMERIC, saved.c_str());
}
