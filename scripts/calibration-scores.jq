# The scores of a calibration summary.json at its selected D0, as tab-separated fields: selected D0,
# penalty minimum, RMS / counting floor, holdup, mean stay and crossing rate errors, KS, rule.
# Shared by scripts/regimes.sh and scripts/calibration-convergence.sh.
def pct: if . == null then "n/a" else (. * 1000 | round / 10 | tostring) + "%" end;
.selected_d0 as $d | (.d0[] | select(.value == $d)) as $x |
[($d | tostring), (.penalty_minimum_d0 | tostring), ($x.rms_over_floor * 100 | round / 100 | tostring),
 ($x.holdup_relative_error | pct), ($x.residence_time_mean_relative_error | pct),
 ($x.crossing_rate_relative_error | pct), ($x.rtd_ks_distance * 1000 | round / 1000 | tostring),
 (if .selection.rule_satisfied then "met" else "not met" end)] | @tsv
