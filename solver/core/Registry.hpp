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

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace rcfd {

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

  static std::vector<std::string> names() {
    std::vector<std::string> out;
    for (const auto& [name, entry] : table()) out.push_back(name);
    return out;  // std::map keeps them sorted
  }

  static const std::map<std::string, Entry>& entries() { return table(); }

  static std::string unknownNameMessage(const std::string& name) {
    std::string msg = "unknown name \"" + name + "\"; valid names are:";
    for (const auto& n : names()) msg += " " + n;
    return msg;
  }

 private:
  static std::map<std::string, Entry>& table() {
    static std::map<std::string, Entry> instance;  // constructed on first use: safe from static init
    return instance;
  }
};

}  // namespace rcfd
