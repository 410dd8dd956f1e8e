#include "tracers/TracerEffect.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/Errors.hpp"

namespace rcfd {
namespace {
std::map<std::string, TracerEffectRegistry::Entry>& table() {
  static std::map<std::string, TracerEffectRegistry::Entry> instance;
  return instance;
}
std::string validNames() {
  std::string out;
  for (const auto& [name, e] : table()) out += (out.empty() ? "" : ", ") + name;
  return out;
}
}  // namespace

bool TracerEffectRegistry::add(const std::string& name, std::vector<std::string> needs, int order,
                               std::string doc, Factory factory, bool readsVelocitySpread,
                               bool velocitySpreadOptional) {
  auto [it, inserted] = table().emplace(name, Entry{std::move(doc), std::move(needs), order, std::move(factory),
                                                    readsVelocitySpread, velocitySpreadOptional});
  if (!inserted) throw std::logic_error("tracer effect registered twice: " + name);
  return true;
}

const std::map<std::string, TracerEffectRegistry::Entry>& TracerEffectRegistry::entries() { return table(); }

bool TracerEffectRegistry::contains(const std::string& name) { return table().count(name) > 0; }

std::vector<std::string> TracerEffectRegistry::resolve(const std::vector<std::string>& requested) {
  std::vector<Violation> problems;
  std::vector<std::string> chosen;
  for (std::size_t i = 0; i < requested.size(); ++i) {
    const auto& name = requested[i];
    if (!isTracerStageEffect(name)) continue;
    if (!contains(name)) {
      problems.push_back({"/effects/" + std::to_string(i),
                          "unknown tracer effect \"" + name + "\"; valid tracer effects are: " + validNames()});
      continue;
    }
    chosen.push_back(name);
  }
  for (const auto& name : chosen) {
    for (const auto& need : table().at(name).needs) {
      if (std::find(requested.begin(), requested.end(), need) == requested.end()) {
        problems.push_back({"/effects", "effect \"" + name + "\" needs \"" + need + "\"; add it to the list"});
      }
    }
  }
  if (!problems.empty()) throw InputError("scene", problems);
  // Dependencies first, then the registered order, then the name: a fixed, documented sequence.
  std::stable_sort(chosen.begin(), chosen.end(), [](const std::string& a, const std::string& b) {
    const auto& ea = table().at(a);
    const auto& eb = table().at(b);
    return ea.order != eb.order ? ea.order < eb.order : a < b;
  });
  return chosen;
}

bool TracerEffectRegistry::needsVelocitySpread(const std::vector<std::string>& effects) {
  return std::any_of(effects.begin(), effects.end(), [](const std::string& name) {
    const auto it = table().find(name);
    return it != table().end() && it->second.readsVelocitySpread;
  });
}

bool TracerEffectRegistry::requiresVelocitySpread(const std::vector<std::string>& effects) {
  return std::any_of(effects.begin(), effects.end(), [](const std::string& name) {
    const auto it = table().find(name);
    return it != table().end() && it->second.readsVelocitySpread && !it->second.velocitySpreadOptional;
  });
}

bool isTracerStageEffect(const std::string& name) {
  static const std::vector<std::string> otherStages = {"gas", "drag", "smoothing", "rolling_friction"};
  return std::find(otherStages.begin(), otherStages.end(), name) == otherStages.end();
}

}  // namespace rcfd
