# The arm randomisations the randomisation benchmarks compare (sourced, not run): each flag alone at
# the range the README suggests, in RANDOMIZE_ORDER, and all of them together in RANDOMIZE_ALL; kp_0.25-1.5
# is a wider stiffness range for the transfer benchmark only.
RANDOMIZE_ALL=(--env.randomize.kp_scale=[0.5,1.5] --env.randomize.latency=[0,0.04]
  --env.randomize.hand_tilt_deg=3 --env.randomize.eef_pos_noise=0.001)
declare -A RANDOMIZE_SETTINGS=(
  [none]=""
  [kp_0.5-1.5]="${RANDOMIZE_ALL[0]}"
  [latency_0-40ms]="${RANDOMIZE_ALL[1]}"
  [tilt_3deg]="${RANDOMIZE_ALL[2]}"
  [noise_1mm]="${RANDOMIZE_ALL[3]}"
  [all]="${RANDOMIZE_ALL[*]}"
  [kp_0.25-1.5]="--env.randomize.kp_scale=[0.25,1.5]"  # wider: in a traced franky-sim trial the hand moved 1.1 mm in the first period of a step where the training arm moved 3.5 mm
)
RANDOMIZE_ORDER=(none kp_0.5-1.5 latency_0-40ms tilt_3deg noise_1mm all)
