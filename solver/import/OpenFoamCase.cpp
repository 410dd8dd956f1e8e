#include "import/OpenFoamCase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "core/Errors.hpp"
#include "import/FoamFile.hpp"

namespace rcfd::openfoam {
namespace fs = std::filesystem;

namespace {

std::optional<double> parseNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

bool isDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

std::vector<WrittenTime> writtenTimes(const fs::path& dir) {
  std::vector<WrittenTime> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    if (const auto v = parseNumber(name)) out.push_back({name, *v});
  }
  std::sort(out.begin(), out.end(), [](const WrittenTime& a, const WrittenTime& b) { return a.value < b.value; });
  return out;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string firstPresent(const fs::path& dir, const std::vector<std::string>& names) {
  for (const auto& n : names)
    if (FoamFile::locate(dir / n)) return n;
  return {};
}

}  // namespace

TimeRange TimeRange::parse(const std::string& text, const std::string& option) {
  const auto colon = text.find(':');
  const auto bad = [&] {
    return InputError(option, "", "\"" + text + "\" is not a time range: give A:B, A: or :B in seconds (e.g. 0.5:2.5)");
  };
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) throw bad();
  TimeRange r;
  const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
  if (!a.empty()) {
    r.first = parseNumber(a);
    if (!r.first) throw bad();
  }
  if (!b.empty()) {
    r.last = parseNumber(b);
    if (!r.last) throw bad();
  }
  if (!r.given()) throw bad();
  if (r.first && r.last && *r.first > *r.last)
    throw InputError(option, "", "\"" + text + "\": the first time is after the last");
  return r;
}

bool TimeRange::contains(double t) const {
  // Written time names are rounded to OpenFOAM's timePrecision: compare with a small tolerance.
  const double eps = 1e-9 * std::max(1.0, std::abs(t));
  if (!given()) return t != 0.0;
  return (!first || t >= *first - eps) && (!last || t <= *last + eps);
}

OpenFoamCase OpenFoamCase::open(const fs::path& root, const TimeRange& range, const std::string& cloudName) {
  if (!isDirectory(root)) throw InputError(root.string(), "", "not a directory (an OpenFOAM case)");
  OpenFoamCase c;
  c.root = root;
  const auto selected = [&](const fs::path& dir) {
    std::vector<WrittenTime> out;
    for (const auto& t : writtenTimes(dir))
      if (range.contains(t.value)) out.push_back(t);
    return out;
  };
  const bool rootMesh = FoamFile::locate(root / "constant/polyMesh/points").has_value();
  std::vector<std::pair<int, fs::path>> processors;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.rfind("processor", 0) == 0 && name.size() > 9 &&
        name.find_first_not_of("0123456789", 9) == std::string::npos)
      processors.emplace_back(std::stoi(name.substr(9)), entry.path());
  }
  std::sort(processors.begin(), processors.end());
  if (rootMesh && (!selected(root).empty() || processors.empty())) {
    c.parts = {root};
  } else if (!processors.empty()) {
    c.decomposed = true;
    for (std::size_t i = 0; i < processors.size(); ++i) {
      if (processors[i].first != int(i))
        throw InputError(root.string(), "", "processor directories must be processor0 .. processor" +
                                                std::to_string(processors.size() - 1) + ": processor" +
                                                std::to_string(i) + " is missing");
      c.parts.push_back(processors[i].second);
      if (!FoamFile::locate(processors[i].second / "constant/polyMesh/points"))
        throw InputError((processors[i].second / "constant/polyMesh/points").string(), "",
                         "no such file: each processor directory needs its mesh");
    }
  } else {
    throw InputError((root / "constant/polyMesh/points").string(), "",
                     "no mesh: expected constant/polyMesh/ (reconstructed) or processor*/constant/polyMesh/ (decomposed)");
  }

  c.times = selected(c.parts.front());
  if (c.times.empty())
    throw InputError(c.parts.front().string(), "",
                     range.given() ? "no written time in the selected range" : "no written time after 0");
  for (std::size_t p = 1; p < c.parts.size(); ++p) {
    for (const auto& t : c.times)
      if (!isDirectory(c.parts[p] / t.name))
        throw InputError((c.parts[p] / t.name).string(), "", "missing: every processor must hold every written time");
  }

  std::set<std::string> clouds;
  for (const auto& part : c.parts)
    for (const auto& t : c.times)
      for (const auto& entry : fs::directory_iterator(part / t.name / "lagrangian", ec))
        if (entry.is_directory()) clouds.insert(entry.path().filename().string());
  if (!cloudName.empty()) {
    if (!clouds.count(cloudName))
      throw InputError(root.string(), "cloud", "no Lagrangian cloud \"" + cloudName + "\" in the selected times" +
                                                   (clouds.empty() ? std::string() : " (found: " + joined({clouds.begin(), clouds.end()}) + ")"));
    c.cloud = cloudName;
  } else if (clouds.size() == 1) {
    c.cloud = *clouds.begin();
  } else if (clouds.size() > 1) {
    throw InputError(root.string(), "cloud", "several Lagrangian clouds (" + joined({clouds.begin(), clouds.end()}) +
                                                 "): choose one with --cloud");
  }

  const fs::path first = c.timeDir(0, c.times.front());
  c.gasVelocityField = firstPresent(first, kGasVelocityNames);
  if (c.gasVelocityField.empty())
    throw InputError(first.string(), "gas velocity", "no gas velocity field: expected one of " + joined(kGasVelocityNames));
  c.pressureField = firstPresent(first, kPressureNames);
  if (c.cloud.empty()) {
    c.particleFractionField = firstPresent(first, kParticleFractionNames);
    c.particleSource = ParticleSource::EulerianFraction;
    if (c.particleFractionField.empty()) {
      c.particleFractionField = firstPresent(first, kVoidFractionNames);
      c.particleSource = ParticleSource::EulerianVoidFraction;
    }
    if (c.particleFractionField.empty())
      throw InputError(first.string(), "particle phase",
                       "no Lagrangian cloud (lagrangian/<cloud>/) and no particle volume fraction: expected one of " +
                           joined(kParticleFractionNames) + ", " + joined(kVoidFractionNames));
    c.particleVelocityField = firstPresent(first, kParticleVelocityNames);
    if (c.particleVelocityField.empty() || c.particleVelocityField == c.gasVelocityField)
      throw InputError(first.string(), "particle velocity",
                       "no particle velocity field: expected one of " + joined(kParticleVelocityNames));
  }
  return c;
}

}  // namespace rcfd::openfoam
