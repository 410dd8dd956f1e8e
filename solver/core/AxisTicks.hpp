#pragma once
/// \file AxisTicks.hpp
/// Round numbers for the axes of every figure rcfd draws (SvgDocument::axes and the figures that tick an
/// axis themselves), and durations as a person writes them for figure titles: a reader compares ticks
/// at 0.05, 0.1, 0.15 at a glance, not at 0.0615, 0.123, 0.184, and reads "after 10 min", not
/// "after 600.000000 s".

#include <string>
#include <vector>

namespace rcfd {

/// 1, 2 or 5 times a power of ten, the one nearest to `raw` (> 0) on a log scale.
double niceStep(double raw);

/// The ticks of an axis over [lo, hi]: every multiple of niceStep((hi - lo) / approxIntervals) inside the
/// range (ends included when they are such multiples), ascending. A value within a millionth of a step of
/// zero is exactly 0. An empty or inverted range gives no tick.
std::vector<double> niceTicks(double lo, double hi, int approxIntervals = 5);

/// The step between the ticks niceTicks() places (0 for fewer than two ticks).
double tickStep(const std::vector<double>& ticks);

/// A tick's label with as many decimals as the tick step needs and no trailing zeros: "0.05", "0.1",
/// "0.15", "20"; exponent form for steps below 1e-4 or from 1e6 on ("2e-05").
std::string tickLabel(double value, double step);

/// A duration as a person writes it in a title (not the fixed-width clock of the progress lines,
/// jobs/Progress.hpp): below a minute in seconds with at most 3 significant digits
/// ("2.5 s", "45 s", "0.25 s"); below an hour in minutes and whole seconds ("10 min", "1 min 30 s");
/// from an hour on in hours and whole minutes ("1 h", "2 h 15 min").
std::string durationLabel(double seconds);

}  // namespace rcfd
