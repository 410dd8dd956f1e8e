#pragma once
/// \file DemParallel.hpp
/// Below this many particles the DEM loops run on one thread: an OpenMP barrier costs more than the
/// work, and far more on an oversubscribed machine. Results do not depend on it (docs/dem.md).
namespace rcfd {
inline constexpr long kDemParallelMinParticles = 2048;
}  // namespace rcfd
