#pragma once
/// \file RecurrencePlot.hpp
/// The recurrence plot (the paper's Fig. 6): R(t_i, t_j) as a heat map over the sampled time in seconds,
/// block-averaged to at most ~400 x 400 cells, embedded as one PNG image so the SVG stays small.

#include <Eigen/Core>
#include <string>

#include "core/Svg.hpp"

namespace rcfd {

/// R averaged over square blocks of `factor` x `factor` frames, factor = ceil(N / maxCells).
Eigen::MatrixXd downsampleRecurrence(const Eigen::MatrixXf& R, int maxCells, int* factor = nullptr);

/// The figure: t_i [s] across, t_j [s] up, viridis colours from R = 0 (dark) to 1 (yellow).
SvgDocument recurrencePlot(const Eigen::MatrixXf& R, double dtRec, const std::string& title,
                           int maxCells = 400);

}  // namespace rcfd
