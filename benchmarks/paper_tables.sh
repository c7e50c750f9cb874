#!/usr/bin/env bash
# Every paper table of docs/results.md, made from scratch in the published protocol, one after the
# other, each a single igen-table command (3 training seeds, checkpoint chosen on validation
# trials, reported on test trials). Hours of CPU per table: run it at low priority and rerun it to
# resume; a finished table is written to docs/results/<name>.json and docs/results.md re-rendered.
#
#   nice -n 10 bash benchmarks/paper_tables.sh                 # every table, in the order below
#   nice -n 10 bash benchmarks/paper_tables.sh nut_insertion   # the tables named
#   DRY_RUN=true bash benchmarks/paper_tables.sh coffee        # the commands each would run
#
# block_grasp_randomized is the Block Grasp table generated on randomised arms (the data that
# transfer, docs/benchmarks.md), and block_grasp_randomized_rehearsal runs its sim-to-real rows through
# igen-eval, the MuJoCo arm with a rendered D415 and franky on franky-sim (igen-rehearse, every
# training seed; franky runs in real time, so nothing else should run beside it). It trains only the
# paper's five sim-to-real rows, the ones the rehearsal runs, 6000 steps each: at Block Grasp's 2000
# the randomised I-Gen row passed 47/60 rehearsal trials through franky, at 6000 55/60
# (docs/benchmarks.md, "A longer training budget").
#
# Every row of a table trains the same way: its budget (the in-hand tasks and Nut-and-Peg train 5000
# steps, Block Grasp the paper's 2000, Block Grasp on randomised arms 6000) plus PROTOCOL, the
# settings every table shares.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=${OUT_ROOT:-outputs/tables}
bin=.venv/bin
PROTOCOL=(${PROTOCOL:-})
long=(--train.steps=5000 --train.save_freq=1000)
# the four arm randomisations of benchmarks/randomization_settings.sh, as igen-table's --randomize list
RANDOMIZE='["--env.randomize.kp_scale=[0.5,1.5]","--env.randomize.latency=[0,0.04]","--env.randomize.hand_tilt_deg=3","--env.randomize.eef_pos_noise=0.001"]'
REHEARSALS=(block_grasp_randomized_rehearsal)
# the paper's five sim-to-real rows: the only ones the rehearsal runs, so the only ones this table trains
SIM_TO_REAL_ROWS='[base,source_int,mg_demo,igen_no_policy,igen]'
declare -A TABLES=(
  [block_grasp]="--task=block_grasp"
  [nut_insertion]="--task=nut_insertion ${long[*]}"
  [nut_insertion_contact_position]="--task=nut_insertion --reveal=contact_position ${long[*]}"
  [two_piece_assembly]="--task=two_piece_assembly ${long[*]}"
  [two_piece_assembly_direction]="--task=two_piece_assembly --reveal=direction ${long[*]}"
  [coffee]="--task=coffee ${long[*]}"
  [two_piece_assembly_scaling]="--task=two_piece_assembly --table=scaling ${long[*]}"
  [nut_and_peg]="--task=nut_and_peg ${long[*]}"
  [block_grasp_randomized]="--task=block_grasp --randomize=${RANDOMIZE} --variants=${SIM_TO_REAL_ROWS} --train.steps=6000 --train.save_freq=1000"
)
ORDER=(block_grasp nut_insertion nut_insertion_contact_position block_grasp_randomized
  block_grasp_randomized_rehearsal two_piece_assembly coffee two_piece_assembly_direction
  two_piece_assembly_scaling nut_and_peg)
names=("$@")
[ ${#names[@]} -gt 0 ] || names=("${ORDER[@]}")
is_rehearsal() { [[ " ${REHEARSALS[*]} " == *" $1 "* ]]; }
for name in "${names[@]}"; do
  [ -n "${TABLES[$name]+set}" ] || is_rehearsal "$name" || { echo "unknown table '$name'; one of: ${ORDER[*]}"; exit 2; }
done
mkdir -p "$root"
for name in "${names[@]}"; do
  if is_rehearsal "$name"; then
    table=$root/${name%_rehearsal}
    command=("$bin/igen-rehearse" --table_dir="$table")
    if [ "${DRY_RUN:-false}" = true ]; then echo "${command[*]}"; continue; fi
    [ -e "$table/table_config.json" ] && [ -n "$(ls "$table"/results/*.json 2>/dev/null)" ] \
      || { echo "$(date +%T) $name: its table $table is not finished; run that first"; exit 1; }
  else
    read -r -a flags <<< "${TABLES[$name]}"
    command=("$bin/igen-table" "${flags[@]}" "${PROTOCOL[@]}" --output_dir="$root/$name" --dry_run="${DRY_RUN:-false}")
  fi
  echo "$(date +%T) $name: ${command[*]}"
  if [ "${DRY_RUN:-false}" = true ]; then "${command[@]}"; else "${command[@]}" >> "$root/$name.log" 2>&1; fi
done
