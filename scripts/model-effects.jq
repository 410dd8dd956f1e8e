# The scene_patch that selects a tracer motion model on a scene (jq --arg model M -f this SCENE.json):
#   mean     the scene as it is: Eq. (9) with Eq. (10)'s random-walk relaxation
#   streams  velocity_streams added after transport (the two-stream velocity)
#   relax    Eq. (10) replaced by directed_relaxation (the directed flux down the excess gradient)
# Shared by scripts/regimes.sh and scripts/calibration-convergence.sh.
if $model == "mean" then {}
elif $model == "streams" then
  {effects: (.effects | (.[0:index("transport") + 1] + ["velocity_streams"] + .[index("transport") + 1:]))}
elif $model == "relax" then
  {effects: (.effects | map(if . == "fluctuation" then "directed_relaxation" else . end))}
else error("unknown model \($model): mean, streams or relax") end
