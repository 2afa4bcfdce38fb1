// Doubles as text and back, whatever the locale, with the bytes of C++17's <charconv>: the table
// file and the learning curves must read the same on every compiler a user builds with. GCC 10's
// libstdc++ (Debian 11; Noetic's GCC 9 likewise) has no floating-point std::to_chars or
// std::from_chars; there the fallback below, built on the C library (correctly rounded in glibc),
// writes and reads the same bytes. Which one runs is chosen at compile time (__cpp_lib_to_chars).
#pragma once

#include <charconv>
#include <string>

namespace cartpole_qlearning
{
// std::to_chars(first, last, value): the shortest text that reads back as the same double (fixed
// or scientific, whichever is shorter; fixed on a tie). 32 characters always suffice.
std::to_chars_result writeShortest(char* first, char* last, double value);
// std::to_chars(first, last, value, std::chars_format::general, precision): printf's %.{precision}g.
std::to_chars_result writeGeneral(char* first, char* last, double value, int precision);
// std::from_chars(first, last, value) (general format): an optional '-', no '+', no leading
// space, no hexadecimal; the value is left as it was unless ec is std::errc().
std::from_chars_result readDouble(const char* first, const char* last, double& value);

// writeShortest as a string.
std::string shortestText(double value);

// The fallback itself, always built, so that a test can hold it to the standard library's bytes
// where both exist.
namespace number_text_fallback
{
std::to_chars_result writeShortest(char* first, char* last, double value);
std::to_chars_result writeGeneral(char* first, char* last, double value, int precision);
std::from_chars_result readDouble(const char* first, const char* last, double& value);
}  // namespace number_text_fallback

// Whether writeShortest and the others above are the standard library's (else the fallback's).
bool numberTextIsStandard();
}  // namespace cartpole_qlearning
