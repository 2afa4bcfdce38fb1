#include "cartpole_qlearning/io/number_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <locale.h>

namespace cartpole_qlearning
{
namespace number_text_fallback
{
namespace
{
// The "C" locale for this thread while it lives: printf and strtod then write and read '.' as
// the decimal point whatever locale the process set (std::to_chars and from_chars ignore it).
class CLocale
{
public:
  CLocale() : previous_(uselocale(cLocale())) {}
  ~CLocale()
  {
    uselocale(previous_);
  }
  CLocale(const CLocale&) = delete;
  CLocale& operator=(const CLocale&) = delete;

private:
  static locale_t cLocale()
  {
    static const locale_t c = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(nullptr));
    return c;
  }
  locale_t previous_;
};

std::to_chars_result copyOut(char* first, char* last, const char* text, std::size_t size)
{
  if (static_cast<std::size_t>(last - first) < size)
    return {last, std::errc::value_too_large};
  std::memcpy(first, text, size);
  return {first + size, std::errc()};
}

// A positive finite double as decimal digits (no trailing zeros) and the power of ten of the first.
struct Decimal
{
  char digits[24];
  int count = 0;
  int exponent = 0;
};

// The digits of printf's "%.*e" text ("d.ddde+XX").
Decimal parseScientific(const char* text)
{
  Decimal d;
  const char* at = text;
  for (; *at != 'e'; ++at)
  {
    if (*at != '.')
      d.digits[d.count++] = *at;
  }
  d.exponent = std::atoi(at + 1);
  return d;
}

std::string scientificText(const Decimal& d)
{
  std::string text(1, d.digits[0]);
  if (d.count > 1)
    text.append(".").append(d.digits + 1, d.digits + d.count);
  char exponent[16];
  std::snprintf(exponent, sizeof exponent, "e%c%02d", d.exponent < 0 ? '-' : '+', std::abs(d.exponent));
  return text + exponent;
}

double parse(const std::string& text)
{
  return std::strtod(text.c_str(), nullptr);
}

// The next P-digit decimal above (step +1) or below (step -1) d.
Decimal neighbour(Decimal d, int step)
{
  int i = d.count - 1;
  if (step > 0)
  {
    while (i >= 0 && d.digits[i] == '9')
      d.digits[i--] = '0';
    if (i < 0)
    {
      d.digits[0] = '1';  // 9.99 -> 10.0: one digit more, and the 0s go
      ++d.exponent;
    }
    else
      ++d.digits[i];
  }
  else
  {
    while (i >= 0 && d.digits[i] == '0')
      d.digits[i--] = '9';
    --d.digits[i];  // the first digit is never 0
    if (d.digits[0] == '0')
    {
      std::memmove(d.digits, d.digits + 1, static_cast<std::size_t>(d.count - 1));
      d.digits[d.count - 1] = '9';  // 1.00 -> 0.999: 9.99 a power of ten lower
      --d.exponent;
    }
  }
  return d;
}

// The P-digit decimal nearest to value (> 0, finite) that reads back as value, if one does: the
// correctly rounded one, else its neighbour on the other side of value (the interval that rounds
// to value is narrower below a power of two than above it); no other P-digit decimal can.
bool readsBack(double value, int precision, Decimal& d)
{
  char text[48];
  std::snprintf(text, sizeof text, "%.*e", precision - 1, value);
  d = parseScientific(text);
  const double back = std::strtod(text, nullptr);
  if (back == value)
    return true;
  const Decimal other = neighbour(d, back > value ? -1 : +1);
  if (parse(scientificText(other)) != value)
    return false;
  d = other;
  return true;
}

// The shortest decimal that reads back as value (> 0, finite), and of those of that length the
// nearest: what std::to_chars (Ryu in libstdc++) writes. Whether a P-digit decimal reads back only
// grows with P (one of P digits is one of P + 1), so the length is found by bisection; 17 digits
// always read back.
Decimal shortest(double value)
{
  int low = 1;
  int high = 17;
  Decimal d;
  while (low < high)
  {
    const int middle = (low + high) / 2;
    if (readsBack(value, middle, d))
      high = middle;
    else
      low = middle + 1;
  }
  readsBack(value, low, d);
  while (d.count > 1 && d.digits[d.count - 1] == '0')
    --d.count;
  return d;
}
}  // namespace

std::to_chars_result writeShortest(char* first, char* last, double value)
{
  if (std::isnan(value))
    return copyOut(first, last, std::signbit(value) ? "-nan" : "nan", std::signbit(value) ? 4 : 3);
  if (std::isinf(value))
    return copyOut(first, last, value < 0 ? "-inf" : "inf", value < 0 ? 4 : 3);
  if (value == 0.0)
    return copyOut(first, last, std::signbit(value) ? "-0" : "0", std::signbit(value) ? 2 : 1);
  const CLocale c_locale;
  const Decimal d = shortest(std::fabs(value));
  std::string text = value < 0 ? "-" : "";
  // Fixed or scientific, whichever is shorter, fixed on a tie (C++17 [charconv.to.chars]).
  const int scientific_size = d.count + (d.count > 1 ? 1 : 0) + 2 + (std::abs(d.exponent) >= 100 ? 3 : 2);
  int fixed_size = 0;
  if (d.exponent >= d.count - 1)
    fixed_size = d.exponent + 1;
  else if (d.exponent >= 0)
    fixed_size = d.count + 1;
  else
    fixed_size = d.count - d.exponent + 1;
  if (fixed_size > scientific_size)
    text += scientificText(d);
  else if (d.exponent >= d.count - 1)
  {
    // A whole number: printf's "%.0f", the double's exact digits, as std::to_chars writes them
    // (not the shortest digits padded with 0s).
    char whole[48];
    std::snprintf(whole, sizeof whole, "%.0f", std::fabs(value));
    text += whole;
  }
  else if (d.exponent >= 0)
  {
    const auto point = static_cast<std::size_t>(d.exponent + 1);
    text.append(d.digits, point).append(".").append(d.digits + point, d.digits + d.count);
  }
  else
    text.append("0.").append(static_cast<std::size_t>(-d.exponent - 1), '0').append(d.digits, d.digits + d.count);
  return copyOut(first, last, text.data(), text.size());
}

std::to_chars_result writeGeneral(char* first, char* last, double value, int precision)
{
  const CLocale c_locale;
  char text[400];  // %.Ng of a double: at most 17 significant digits print as non-zero, but the
                   // precision asks for as many as it likes (zeros are dropped by %g)
  const int size = std::snprintf(text, sizeof text, "%.*g", precision, value);
  if (size < 0 || static_cast<std::size_t>(size) >= sizeof text)
    return {last, std::errc::value_too_large};
  return copyOut(first, last, text, static_cast<std::size_t>(size));
}

namespace
{
bool isDigit(char c)
{
  return c >= '0' && c <= '9';
}

// Whether [at, last) starts with word, ignoring case (word in lower case).
bool startsWith(const char* at, const char* last, const char* word)
{
  const std::size_t size = std::strlen(word);
  if (static_cast<std::size_t>(last - at) < size)
    return false;
  for (std::size_t i = 0; i < size; ++i)
  {
    const char c = at[i] >= 'A' && at[i] <= 'Z' ? static_cast<char>(at[i] - 'A' + 'a') : at[i];
    if (c != word[i])
      return false;
  }
  return true;
}

// The end of the longest prefix of [at, last) that from_chars' general format reads (after the
// sign), or at itself when none.
const char* patternEnd(const char* at, const char* last)
{
  const char* p = at;
  std::size_t digits = 0;
  while (p != last && isDigit(*p))
    ++p, ++digits;
  if (p != last && *p == '.')
  {
    const char* fraction = p + 1;
    while (fraction != last && isDigit(*fraction))
      ++fraction, ++digits;
    if (digits > 0)
      p = fraction;
  }
  if (digits > 0)
  {
    if (p != last && (*p == 'e' || *p == 'E'))
    {
      const char* exponent = p + 1;
      if (exponent != last && (*exponent == '+' || *exponent == '-'))
        ++exponent;
      if (exponent != last && isDigit(*exponent))
      {
        while (exponent != last && isDigit(*exponent))
          ++exponent;
        p = exponent;
      }
    }
    return p;
  }
  if (startsWith(at, last, "infinity"))
    return at + 8;
  if (startsWith(at, last, "inf"))
    return at + 3;
  if (startsWith(at, last, "nan"))
  {
    p = at + 3;
    if (p != last && *p == '(')
    {
      const char* q = p + 1;
      while (q != last && (isDigit(*q) || (*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || *q == '_'))
        ++q;
      if (q != last && *q == ')')
        p = q + 1;
    }
    return p;
  }
  return at;
}
}  // namespace

std::from_chars_result readDouble(const char* first, const char* last, double& value)
{
  const char* at = first;
  if (at != last && *at == '-')
    ++at;
  const char* end = patternEnd(at, last);
  if (end == at)
    return {first, std::errc::invalid_argument};
  // strtod reads exactly the text matched (it alone would also take spaces, '+' and hex).
  const std::string text(first, end);
  const CLocale c_locale;
  const int saved_errno = errno;
  errno = 0;
  char* parsed_end = nullptr;
  const double parsed = std::strtod(text.c_str(), &parsed_end);
  const bool out_of_range = errno == ERANGE && (parsed == 0.0 || std::isinf(parsed));
  errno = saved_errno;
  if (out_of_range)
    return {end, std::errc::result_out_of_range};
  value = parsed;
  return {end, std::errc()};
}
}  // namespace number_text_fallback

#if defined(__cpp_lib_to_chars)
std::to_chars_result writeShortest(char* first, char* last, double value)
{
  return std::to_chars(first, last, value);
}

std::to_chars_result writeGeneral(char* first, char* last, double value, int precision)
{
  return std::to_chars(first, last, value, std::chars_format::general, precision);
}

std::from_chars_result readDouble(const char* first, const char* last, double& value)
{
  return std::from_chars(first, last, value);
}

bool numberTextIsStandard()
{
  return true;
}
#else
std::to_chars_result writeShortest(char* first, char* last, double value)
{
  return number_text_fallback::writeShortest(first, last, value);
}

std::to_chars_result writeGeneral(char* first, char* last, double value, int precision)
{
  return number_text_fallback::writeGeneral(first, last, value, precision);
}

std::from_chars_result readDouble(const char* first, const char* last, double& value)
{
  return number_text_fallback::readDouble(first, last, value);
}

bool numberTextIsStandard()
{
  return false;
}
#endif

std::string shortestText(double value)
{
  char text[32];
  const std::to_chars_result written = writeShortest(text, text + sizeof text, value);
  return std::string(text, written.ptr);
}
}  // namespace cartpole_qlearning
