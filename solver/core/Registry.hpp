#pragma once
/// \file Registry.hpp
/// Run-time selection by name, after OpenFOAM's runTimeSelectionTable and LAMMPS styles: a model class
/// registers itself with one line in its own .cpp, and a scene picks it by name. An unknown name is
/// refused with the sorted list of valid names -- that message is the user interface.
///
///   // in FluctuationModel.hpp
///   using FluctuationModelRegistry = Registry<FluctuationModel, const Scene&>;
///   // in FluctuationModels.cpp
///   static const bool registered = FluctuationModelRegistry::add(
///       "lichtenegger_pirker", "Eq. (10): n sqrt(D0 dalpha / (6 pi dt alpha_P))",
///       [](const Scene& s) { return std::make_unique<LichteneggerPirkerFluctuation>(s); });
///
/// A choice between code paths that share their data (an enum a kernel switches on, where a model
/// object would only wrap a flag) is a table of NamedValue instead, parsed with the same message:
///
///   inline constexpr std::array<NamedValue<RecurrenceNorm>, 3> kRecurrenceNorms{{
///       {"l2", RecurrenceNorm::L2, "Eq. (6)"}, ...}};
///   const RecurrenceNorm n = parseNamedValue(kRecurrenceNorms, name, "rcfd-solve recurrence", "--norm");

#include <algorithm>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/Errors.hpp"

namespace rcfd {

/// The one wording of an unknown name, for registries and tables alike: the name and the sorted list
/// of valid names.
inline std::string unknownNameMessage(const std::string& name, std::vector<std::string> valid) {
  std::sort(valid.begin(), valid.end());
  std::string msg = "unknown name \"" + name + "\"; valid names are:";
  for (const auto& n : valid) msg += " " + n;
  return msg;
}

template <class Base, class... Args>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Base>(Args...)>;
  struct Entry {
    std::string doc;
    Factory factory;
  };

  /// Registers a model; returns true so it can initialise a static. Registering a name twice throws.
  static bool add(const std::string& name, std::string doc, Factory factory) {
    auto [it, inserted] = table().emplace(name, Entry{std::move(doc), std::move(factory)});
    if (!inserted) throw std::logic_error("model registered twice: " + name);
    return true;
  }

  static bool contains(const std::string& name) { return table().count(name) > 0; }

  /// Builds the model called `name`; std::out_of_range with the valid names if there is none.
  static std::unique_ptr<Base> create(const std::string& name, Args... args) {
    auto it = table().find(name);
    if (it == table().end()) throw std::out_of_range(unknownNameMessage(name));
    return it->second.factory(std::forward<Args>(args)...);
  }

  /// Builds the model called `name`; for an unknown name an InputError at `pointer` of `source` (the
  /// input key that named it, e.g. "/gas/drag_model" of "scene") with the valid names.
  static std::unique_ptr<Base> createAt(const std::string& source, const std::string& pointer,
                                        const std::string& name, Args... args) {
    if (!contains(name)) throw InputError(source, pointer, unknownNameMessage(name));
    return create(name, std::forward<Args>(args)...);
  }

  static std::vector<std::string> names() {
    std::vector<std::string> out;
    for (const auto& [name, entry] : table()) out.push_back(name);
    return out;  // std::map keeps them sorted
  }

  static const std::map<std::string, Entry>& entries() { return table(); }

  static std::string unknownNameMessage(const std::string& name) { return rcfd::unknownNameMessage(name, names()); }

 private:
  static std::map<std::string, Entry>& table() {
    static std::map<std::string, Entry> instance;  // constructed on first use: safe from static init
    return instance;
  }
};

/// One entry of a fixed table of choices by name (see the file comment).
template <class E>
struct NamedValue {
  const char* name;
  E value;
  const char* doc;  ///< one line, for help texts
};

/// The table's names, sorted.
template <class E, std::size_t N>
std::vector<std::string> namesOf(const std::array<NamedValue<E>, N>& table) {
  std::vector<std::string> out;
  for (const auto& entry : table) out.emplace_back(entry.name);
  std::sort(out.begin(), out.end());
  return out;
}

template <class E, std::size_t N>
std::optional<E> findNamedValue(const std::array<NamedValue<E>, N>& table, const std::string& name) {
  for (const auto& entry : table)
    if (name == entry.name) return entry.value;
  return std::nullopt;
}

/// The value called `name`; InputError at `pointer` of `source` with the valid names otherwise.
template <class E, std::size_t N>
E parseNamedValue(const std::array<NamedValue<E>, N>& table, const std::string& name, const std::string& source,
                  const std::string& pointer) {
  if (auto v = findNamedValue(table, name)) return *v;
  throw InputError(source, pointer, unknownNameMessage(name, namesOf(table)));
}

/// The name of `value`; std::logic_error for a value the table lacks (a programming error).
template <class E, std::size_t N>
const char* nameOf(const std::array<NamedValue<E>, N>& table, E value) {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name;
  throw std::logic_error("a value without a name in its table");
}

}  // namespace rcfd
