#pragma once
/// \file FieldValidation.hpp
/// The checks every database passes, whatever its source (HDF5 file, memory, a writer's input):
/// grid attributes, the fluid fraction, frame sizes and finite values. Violations name the dataset
/// or attribute of the HDF5 layout ("/grid@spacing", "/frames/alpha_p").

#include <string>
#include <vector>

#include "core/Errors.hpp"
#include "fields/FieldDatabase.hpp"

namespace rcfd {

/// Appends a violation for each non-finite origin, non-positive or non-finite spacing, non-positive shape.
void validateGrid(const CartesianGrid& grid, std::vector<Violation>& violations);
/// Fluid fraction: one value per cell, each finite and in [0, 1].
void validateFluidFraction(const std::vector<float>& fluidFraction, const CartesianGrid& grid,
                           std::vector<Violation>& violations);
/// dt_rec: finite and > 0.
void validateDtRec(double dtRec, std::vector<Violation>& violations);

/// Throws rcfd::InputError (source `source`) if frame `index` has the wrong sizes for `grid` or holds
/// a NaN or infinity, or an alpha_P outside [0, 1]; the message names the dataset, the frame and the cell (i, j, k).
void checkFrame(const FieldFrame& frame, int index, const CartesianGrid& grid, const std::string& source);

}  // namespace rcfd
