# The arm randomisations the randomisation benchmarks compare (sourced, not run): each flag alone at
# the range the README suggests, in RANDOMIZE_ORDER, and all of them together in RANDOMIZE_ALL.
RANDOMIZE_ALL=(--env.randomize.kp_scale=[0.5,1.5] --env.randomize.latency=[0,0.04]
  --env.randomize.hand_tilt_deg=3 --env.randomize.eef_pos_noise=0.001)
declare -A RANDOMIZE_SETTINGS=(
  [none]=""
  [kp_0.5-1.5]="${RANDOMIZE_ALL[0]}"
  [latency_0-40ms]="${RANDOMIZE_ALL[1]}"
  [tilt_3deg]="${RANDOMIZE_ALL[2]}"
  [noise_1mm]="${RANDOMIZE_ALL[3]}"
  [all]="${RANDOMIZE_ALL[*]}"
)
RANDOMIZE_ORDER=(none kp_0.5-1.5 latency_0-40ms tilt_3deg noise_1mm all)
