#include "recurrence/RecurrencePlot.hpp"

#include <algorithm>

namespace rcfd {

Eigen::MatrixXd downsampleRecurrence(const Eigen::MatrixXf& R, int maxCells, int* factor) {
  const Eigen::Index n = R.rows();
  const Eigen::Index f = std::max<Eigen::Index>(1, (n + maxCells - 1) / std::max(1, maxCells));
  const Eigen::Index m = (n + f - 1) / f;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd count = Eigen::MatrixXd::Zero(m, m);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      out(i / f, j / f) += R(i, j);
      count(i / f, j / f) += 1.0;
    }
  if (factor) *factor = int(f);
  return out.cwiseQuotient(count);
}

SvgDocument recurrencePlot(const Eigen::MatrixXf& R, double dtRec, const std::string& title, int maxCells) {
  const double duration = double(R.rows()) * dtRec;  // frame i covers [i dt, (i + 1) dt)
  SvgDocument svg(0.0, duration, 0.0, duration, 620, 580, 70);
  int factor = 1;
  const Eigen::MatrixXd cells = downsampleRecurrence(R, maxCells, &factor);
  const int m = int(cells.rows());
  std::vector<double> values(std::size_t(m) * std::size_t(m));
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) values[std::size_t(j) * m + i] = cells(i, j);  // x = t_i, y = t_j
  const double covered = double(m) * factor * dtRec;
  svg.heatmapImage(values, m, m, 0.0, covered, 0.0, covered);
  svg.axes("t_i [s]", "t_j [s]");
  svg.textPx(310, 30, title, 14, "middle");
  // Colour bar right of the plot.
  const int steps = 50;
  const double x0 = duration * 1.04, x1 = duration * 1.09;
  for (int k = 0; k < steps; ++k) {
    svg.rect(x0, duration * k / steps, x1, duration * (k + 1) / steps + duration * 0.002,
             colormap((k + 0.5) / steps).hex());
  }
  svg.rect(x0, 0.0, x1, duration, "none", "#000", 1.0);
  svg.text(x1 + duration * 0.01, 0.0, "0", 10);
  svg.text(x1 + duration * 0.01, duration * 0.98, "1", 10);
  svg.text(x0, duration * 1.02, "R", 11);
  return svg;
}

}  // namespace rcfd
