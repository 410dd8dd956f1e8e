# The scene_patch that selects a tracer motion model on a scene (jq --arg model M -f this SCENE.json),
# whichever relaxation the scene itself lists:
#   mean     Eq. (9) with Eq. (10)'s random-walk relaxation (`fluctuation`)
#   streams  the same with velocity_streams added after transport (the two-stream velocity)
#   relax    Eq. (9) with directed_relaxation (the directed flux down the excess gradient)
#   langevin the relax model with langevin_velocity (the velocity spread as an Ornstein-Uhlenbeck
#            fluctuation)
# and each of them with the suffix "-mw" (e.g. mean-mw): the same with rcfd.velocity_interpolation
# "mass_weighted" (the particle flux between cell centres).
# Shared by scripts/regimes.sh and scripts/calibration-convergence.sh.
def relaxation($name): map(if . == "fluctuation" or . == "directed_relaxation" then $name else . end);
def withoutStreams: map(select(. != "velocity_streams" and . != "langevin_velocity"));
($model | endswith("-mw")) as $weighted | ($model | sub("-mw$"; "")) as $model |
(if $model == "mean" then {effects: (.effects | withoutStreams | relaxation("fluctuation"))}
elif $model == "streams" then
  {effects: (.effects | withoutStreams | relaxation("fluctuation")
             | (.[0:index("transport") + 1] + ["velocity_streams"] + .[index("transport") + 1:]))}
elif $model == "relax" then {effects: (.effects | withoutStreams | relaxation("directed_relaxation"))}
elif $model == "langevin" then
  {effects: (.effects | withoutStreams | relaxation("directed_relaxation")
             | (.[0:index("directed_relaxation") + 1] + ["langevin_velocity"] + .[index("directed_relaxation") + 1:]))}
else error("unknown model \($model): mean, streams, relax or langevin, each also with -mw") end)
| if $weighted then . + {rcfd: {velocity_interpolation: "mass_weighted"}} else . end
