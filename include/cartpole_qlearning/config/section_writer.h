// Where settings are written (a table's trained_with: io/yaml_parameters.h's yamlText), and the
// writer of one section over it: the counterpart of ParameterSource and SectionReader, so that what
// is written reads back as the same values.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// Keys are slash-separated paths ("learning/epsilon/start"), given in the order they are to appear:
// the keys of a section (or of a map within it) one after the other.
class ParameterSink
{
public:
  virtual ~ParameterSink() = default;
  // Exactly: the text reads back as the same double.
  virtual void number(const std::string& key, double value) = 0;
  virtual void whole(const std::string& key, std::uint64_t value) = 0;
  virtual void flag(const std::string& key, bool value) = 0;
  // A name from a fixed set (an integrator, a schedule): written as it is.
  virtual void word(const std::string& key, const std::string& value) = 0;
  // Any text (a path, a joint's name): written quoted.
  virtual void text(const std::string& key, const std::string& value) = 0;
  virtual void numbers(const std::string& key, const std::vector<double>& values) = 0;
  virtual void texts(const std::string& key, const std::vector<std::string>& values) = 0;
};

class SectionWriter
{
public:
  SectionWriter(ParameterSink& sink, std::string section) : sink_(sink), section_(std::move(section)) {}

  void write(const std::string& name, double value)
  {
    sink_.number(key(name), value);
  }
  void write(const std::string& name, unsigned value)
  {
    sink_.whole(key(name), value);
  }
  void write(const std::string& name, std::uint64_t value)
  {
    sink_.whole(key(name), value);
  }
  void write(const std::string& name, bool value)
  {
    sink_.flag(key(name), value);
  }
  void write(const std::string& name, const std::string& value)
  {
    sink_.text(key(name), value);
  }
  void write(const std::string& name, const std::vector<double>& values)
  {
    sink_.numbers(key(name), values);
  }
  void write(const std::string& name, const std::vector<std::string>& values)
  {
    sink_.texts(key(name), values);
  }
  template <typename T, std::size_t N>
  void write(const std::string& name, const std::array<T, N>& values)
  {
    sink_.numbers(key(name), std::vector<double>(values.begin(), values.end()));
  }
  void word(const std::string& name, const std::string& value)
  {
    sink_.word(key(name), value);
  }

  std::string key(const std::string& name) const
  {
    return section_.empty() ? name : section_ + "/" + name;
  }

private:
  ParameterSink& sink_;
  std::string section_;
};

}  // namespace cartpole_qlearning
