#pragma once
/// \file AggregationMultigrid.hpp
/// A geometric-aggregation multigrid V-cycle, used as the preconditioner of the pressure CG: level l+1
/// merges the 2x2x2 blocks of level l's cells (a piecewise-constant prolongation P), A_{l+1} = P^T A_l P
/// (Galerkin, so cut cells and alpha_G come along without geometry), symmetric Gauss-Seidel smoothing
/// (forward before, backward after: the cycle is a symmetric operator, as CG needs), a sparse Cholesky
/// on the coarsest level. On the finest level of a large grid the sweeps are hybrid: y-slabs of cells
/// are swept in parallel, each reading the other slabs' values from before the sweep (Jacobi between
/// slabs, Gauss-Seidel inside); the slabs are fixed by the grid, so the result is the same for any
/// number of threads.

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <array>
#include <memory>
#include <vector>

namespace rcfd::gas {

/// Pressure systems of at least this many unknowns run their row loops in parallel: the finest
/// multigrid level's (hybrid) smoothing, residual and prolongation, and the CG's products (below it the
/// OpenMP fork/join costs more than the loop). Measured on the quick slice's 24,000 rows, 2 threads,
/// 0.03 s from a spouting state (3 alternating runs): 3.60 -> 3.46 s with the parallel multigrid
/// residual, 3.38 s with the CG's loops too; the threshold was 150,000 before. 16,384 left the quick
/// slice on 6.67 mm cells (8,832 unknowns) serial: 4,096 gave 3.73/3.77/4.12 s against 3.96/3.86/4.68 s
/// per 0.05 s (3 alternating runs, the same 8.43 CG iterations per solve).
inline constexpr long kParallelPressureRows = 4096;

class AggregationMultigrid {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  /// cellOf[r]: the grid cell (i, j, k) of unknown r; used to build the aggregates once.
  explicit AggregationMultigrid(std::vector<std::array<int, 3>> cellOf);
  ~AggregationMultigrid();

  /// Builds the level matrices for A (same unknowns as cellOf).
  void compute(const Matrix& a);
  /// z = V-cycle applied to r (z = M^-1 r).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  int levels() const { return int(levels_.size()); }

  /// A level's matrix split for Gauss-Seidel: the off-diagonal entries of each row, those of its own
  /// block first (up to `own[r]`), then those of other blocks, and the diagonal (no search for it
  /// inside the sweep). `blockRows` lists the rows of each block in row order; a single block is
  /// classical Gauss-Seidel.
  struct SplitRows {
    std::vector<int> start, own, column;
    std::vector<double> value, diagonal;
    std::vector<std::vector<int>> blockRows;
  };

 private:
  struct Level {
    Matrix a;
    std::vector<int> coarseOf;  ///< aggregate of each unknown on the next level
    int coarseCount = 0;
    SplitRows split;
  };
  void cycle(int l, const Eigen::VectorXd& b, Eigen::VectorXd& x) const;

  std::vector<std::array<int, 3>> cellOf_;
  std::vector<Level> levels_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> coarse_;
};

}  // namespace rcfd::gas
