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
# Two lanes: start it a second time while the first runs. A lane locks the table it runs (flock, let
# go when the lane dies) and the other lane skips that table for the next; a rehearsal runs only
# when no other lane is alive (franky runs in real time), and is skipped otherwise; a lane started while
# it runs waits for it to end before its next table. The tables after
# Block Grasp train at one torch thread, so two lanes' trainings share the two cores without the
# collapse of two 2-thread pools and give the weights they would alone (docs/benchmarks.md).
#
# block_grasp_randomized is the Block Grasp table generated on randomised arms (the data that
# transfer, docs/benchmarks.md), and block_grasp_randomized_rehearsal runs its sim-to-real rows through
# igen-eval, the MuJoCo arm with a rendered D415 and franky on franky-sim (igen-rehearse, every
# training seed; franky runs in real time, so nothing else should run beside it). It trains only the
# paper's five sim-to-real rows, the ones the rehearsal runs, 6000 steps each: at Block Grasp's 2000
# the randomised I-Gen row passed 47/60 rehearsal trials through franky, at 6000 55/60
# (docs/benchmarks.md, "A longer training budget").
#
# A machine can be lost between sessions with its outputs: every table keeps its evaluation reports,
# step times and commits in docs/results/ledger/<name> (version-controlled) as each step finishes, and
# on a new machine restores them and trains no seed whose numbers are on record; only datasets and
# the policy they are generated with are made again. A table already published in
# docs/results/<name>.json is not made again unless REDO names it (REDO=all: every table). The
# rehearsal reads its table's checkpoints, so that table trains again the runs it restores
# (--retrain_restored=true: deterministic, the weights that were tested).
#
# Tables of one task share some trainings (Base and MG Demo of the full and partial tables, the
# scaling table's base policy and its I-Gen 1000 row): a table takes a finished training of a table
# beside it with the same data and command instead of making it again (igen-table --reuse_trainings,
# its records name the source) and evaluates it in its own environment.
#
# Every row of a table trains the same way: its budget (the in-hand tasks and Nut-and-Peg train 5000
# steps, Block Grasp the paper's 2000, Block Grasp on randomised arms 6000), its thread count (Block
# Grasp 2, made before the lanes; every later table 1), its input normaliser (Block Grasp each row's own
# statistics, made before the choice; every later table D's, igen-table's default) plus PROTOCOL, the
# settings every table shares.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=${OUT_ROOT:-outputs/tables}
bin=${BIN:-.venv/bin}  # where igen-table and igen-rehearse are (tests give stand-ins that only log their runs)
PROTOCOL=(${PROTOCOL:-})
long=(--train.steps=5000 --train.save_freq=1000 --train.threads=1)
# the four arm randomisations of benchmarks/randomization_settings.sh, as igen-table's --randomize list
RANDOMIZE='["--env.randomize.kp_scale=[0.5,1.5]","--env.randomize.latency=[0,0.04]","--env.randomize.hand_tilt_deg=3","--env.randomize.eef_pos_noise=0.001"]'
REHEARSALS=(block_grasp_randomized_rehearsal)
# the paper's five sim-to-real rows: the only ones the rehearsal runs, so the only ones this table trains
SIM_TO_REAL_ROWS='[base,source_int,mg_demo,igen_no_policy,igen]'
declare -A TABLES=(
  [block_grasp]="--task=block_grasp --train.threads=2 --observation_stats=own"
  [nut_insertion]="--task=nut_insertion ${long[*]}"
  [nut_insertion_contact_position]="--task=nut_insertion --reveal=contact_position ${long[*]}"
  [two_piece_assembly]="--task=two_piece_assembly ${long[*]}"
  [two_piece_assembly_direction]="--task=two_piece_assembly --reveal=direction ${long[*]}"
  [coffee]="--task=coffee ${long[*]}"
  [two_piece_assembly_scaling]="--task=two_piece_assembly --table=scaling ${long[*]}"
  [nut_and_peg]="--task=nut_and_peg ${long[*]}"
  [block_grasp_randomized]="--task=block_grasp --randomize=${RANDOMIZE} --variants=${SIM_TO_REAL_ROWS} --train.steps=6000 --train.save_freq=1000 --train.threads=1 --retrain_restored=true"
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
locks=$root/.locks
if [ "${DRY_RUN:-false}" != true ]; then
  mkdir -p "$locks"
  exec {lane}> "$locks/lane.$$" && flock "$lane"  # held while this lane lives
  trap 'rm -f "$locks/lane.$$"' EXIT
fi
other_lane_alive() {
  local f
  for f in "$locks"/lane.*; do
    [ "$f" = "$locks/lane.$$" ] && continue
    if flock -n "$f" true; then rm -f "$f"; else return 0; fi  # a lane that died leaves its file unlocked
  done
  return 1
}
for name in "${names[@]}"; do
  if is_rehearsal "$name"; then
    table=$root/${name%_rehearsal}
    command=("$bin/igen-rehearse" --table_dir="$table")
    if [ "${DRY_RUN:-false}" = true ]; then echo "${command[*]}"; continue; fi
    [ -e "$table/table_config.json" ] && [ -n "$(ls "$table"/results/*.json 2>/dev/null)" ] \
      || { echo "$(date +%T) $name: its table $table is not finished; skipped (rerun when it is)"; continue; }
    exec {alone}> "$locks/alone.lock" && flock -x "$alone"  # a lane started from now on waits for it
    if other_lane_alive; then
      exec {alone}>&-
      echo "$(date +%T) $name: runs alone, and another lane is running; skipped"; continue
    fi
  else
    if [ -e "docs/results/$name.json" ] && [ ! -e "$root/$name/table_config.json" ] \
      && [[ " ${REDO:-} " != *" $name "* && "${REDO:-}" != all ]]; then
      echo "$(date +%T) $name: published in docs/results/$name.json; REDO=$name makes it again"; continue
    fi
    read -r -a flags <<< "${TABLES[$name]}"
    command=("$bin/igen-table" "${flags[@]}" "${PROTOCOL[@]}" --output_dir="$root/$name"
      --ledger_dir="docs/results/ledger/$name" --dry_run="${DRY_RUN:-false}")
  fi
  if [ "${DRY_RUN:-false}" = true ]; then echo "$(date +%T) $name: ${command[*]}"; "${command[@]}"; continue; fi
  # a rehearsal another lane runs must run alone: wait for it to end before starting a table
  is_rehearsal "$name" || flock -s "$locks/alone.lock" true
  status=0
  LOG=$root/$name.log flock -n -E 75 "$locks/$name.lock" bash -c 'echo "$(date +%T) $0: $*"; "$@" >> "$LOG" 2>&1' \
    "$name" "${command[@]}" || status=$?
  ! is_rehearsal "$name" || exec {alone}>&-
  if [ "$status" = 75 ]; then echo "$(date +%T) $name: another lane is running it; next"; continue; fi
  [ "$status" = 0 ] || { echo "$(date +%T) $name: failed (exit $status); log $root/$name.log"; exit "$status"; }
done
