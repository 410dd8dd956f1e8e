#include "scene/Scene.hpp"

#include <algorithm>

namespace rcfd {
bool Scene::hasEffect(const std::string& name) const {
  return std::find(effects.begin(), effects.end(), name) != effects.end();
}
}  // namespace rcfd
