#pragma once
/// \file PathFile.hpp
/// Predefined recurrence paths on disk (calibration runs use one fixed path for every D0). Two forms:
/// text (whitespace-separated frame indices, '#' starts a comment) and HDF5 (a 1-D integer dataset
/// `/path`), chosen by the extension (.h5/.hdf5 -> HDF5).

#include <string>

#include "recurrence/RecurrencePath.hpp"

namespace rcfd {

/// Reads a path file; rcfd::InputError naming the file and the entry if it is missing or malformed.
RecurrencePath readPathFile(const std::string& path);
/// Writes a path file (text or HDF5 by extension); rcfd::RunError if it cannot be written.
void writePathFile(const std::string& path, const RecurrencePath& recurrencePath);

}  // namespace rcfd
