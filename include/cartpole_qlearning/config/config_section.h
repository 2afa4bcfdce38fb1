// A section of a settings file as one table: each key listed once, with how it is read (checks
// included), how it is written and one line of documentation. The table drives reading, refusing
// unknown keys, writing (a table's trained_with) and the docs check (test/docs/config_docs_test.cpp),
// so a new key is one line in its section's table.
#pragma once

#include "cartpole_qlearning/config/parameter_source.h"
#include "cartpole_qlearning/config/section_reader.h"
#include "cartpole_qlearning/config/section_writer.h"

#include <functional>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <string>
#include <utility>
#include <vector>

namespace cartpole_qlearning
{
template <typename Params>
struct ConfigKey
{
  std::string name;  // under the section: "gamma", "epsilon/start"
  std::string doc;   // type, unit and meaning, in one line
  // Reads it over params (which holds the defaults and the keys read before it), checking it.
  std::function<void(SectionReader& reader, Params& params)> read;
  // Writes its value, or nothing (a key that says nothing unless set). Empty: never written.
  std::function<void(SectionWriter& writer, const Params& params)> write;
};

template <typename Params>
struct ConfigSection
{
  std::string name;  // "learning"; empty: the file's top level
  std::vector<ConfigKey<Params>> keys;
  // Checks what hangs together once every key is read (Params::validate()); may be empty.
  std::function<void(const SectionReader& reader, const Params& params)> check;

  // Overrides params with what the source sets, refusing an unknown key and a bad value.
  void read(const ParameterSource& source, Params& params) const
  {
    SectionReader reader(source, name);
    for (const ConfigKey<Params>& key : keys)
      key.read(reader, params);
    reader.refuseUnknown();
    if (check)
      check(reader, params);
  }

  void write(ParameterSink& sink, const Params& params) const
  {
    SectionWriter writer(sink, name);
    for (const ConfigKey<Params>& key : keys)
      if (key.write)
        key.write(writer, params);
  }

  // Every key, section included ("learning/gamma"), in the table's order.
  std::vector<std::string> keyNames() const
  {
    std::vector<std::string> names;
    for (const ConfigKey<Params>& key : keys)
      names.push_back(name.empty() ? key.name : name + "/" + key.name);
    return names;
  }
};

// Builders for the common forms. `access` is a generic lambda giving the member of a Params, const
// or not: [](auto& p) -> auto& { return p.gamma; }.

// Read and written as it is (a number, a flag, a list, a text written quoted).
template <typename Params, typename Access>
ConfigKey<Params> plainKey(const std::string& name, const std::string& doc, Access access)
{
  return {name, doc, [name, access](SectionReader& r, Params& p) { r.read(name, access(p)); },
          [name, access](SectionWriter& w, const Params& p) { w.write(name, access(p)); }};
}

// A whole number in [min, max] (unsigned) or >= min (std::uint64_t: max unused).
template <typename Params, typename Access>
ConfigKey<Params> wholeKey(const std::string& name, const std::string& doc, Access access, std::int64_t min,
                           std::int64_t max = 0)
{
  return {name, doc,
          [name, access, min, max](SectionReader& r, Params& p) {
            auto& value = access(p);
            if constexpr (std::is_same_v<std::decay_t<decltype(value)>, unsigned>)
              r.read(name, value, min, max);
            else
            {
              (void)max;  // a std::uint64_t has no upper bound here (clang: the capture is otherwise unused)
              r.read(name, value, min);
            }
          },
          [name, access](SectionWriter& w, const Params& p) { w.write(name, access(p)); }};
}

// An enum by name: toString(value) and parse(text), which throws std::invalid_argument saying what
// is allowed.
template <typename Params, typename Access, typename Parse>
ConfigKey<Params> nameKey(const std::string& name, const std::string& doc, Access access, Parse parse)
{
  return {name, doc,
          [name, access, parse](SectionReader& r, Params& p) {
            std::string text = toString(access(p));
            r.read(name, text);
            try
            {
              access(p) = parse(text);
            }
            catch (const std::invalid_argument& e)
            {
              r.fail(name, "'" + text + "'", e.what());
            }
          },
          [name, access](SectionWriter& w, const Params& p) { w.word(name, toString(access(p))); }};
}

}  // namespace cartpole_qlearning
