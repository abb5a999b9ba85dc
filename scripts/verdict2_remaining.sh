#!/usr/bin/env bash
# Runs what is left of results/verdict2 as one shard (run it twice, SHARD 0 and 1, one per
# core), in the order of results/README.md, each method on the binary its landed runs used:
# the lockless 2aceba9 binary for the methods with Embree in the process (sa-hash,
# sa-resgs, hybrid), the binary of 864af66 for the rest. Finished jobs are skipped, so it
# can be stopped and started again. A 2aceba9 config starts only once both shards have
# finished every config before it (no lock would stop the two shards from running one job
# twice otherwise).
#
#   OLD=/path/to/864af66/saresgs EMB=/path/to/2aceba9/saresgs [PAPER=/path/to/saresgs] \
#     bash scripts/verdict2_remaining.sh SHARD
#
# PAPER (optional): the binary of 5b76fc9, which ran the landed jobs of
# results/grid_paper_preset.json (it takes a lock per job): runs what is left of that grid into
# results/paper_preset first (about 50 minutes a job).
#
# Build the two binaries as results/README.md says (a git worktree per commit, Release).
# Subset configs and the shards' progress marks go to $WORK (default /tmp/verdict2_remaining);
# the shard's log to $WORK/shardSHARD.log.
set -euo pipefail
cd "$(dirname "$0")/.."
me=${1:?usage: verdict2_remaining.sh 0|1}
[ "$me" = 0 ] || [ "$me" = 1 ] || { echo "verdict2_remaining: SHARD must be 0 or 1" >&2; exit 2; }
other=$((1 - me))
old=${OLD:?set OLD to the binary of 864af66}
emb=${EMB:?set EMB to the binary of 2aceba9}
work=${WORK:-/tmp/verdict2_remaining}
mkdir -p "$work"
# The subset configs: a stage file with its methods, seeds and variants narrowed.
/usr/bin/python3 - "$work" <<'EOF'
import json, os, sys
work = sys.argv[1]
def subset(name, stage, methods, seeds, variants=None):
    c = json.load(open(f"results/grid_verdict2_stage{stage}.json"))
    c.update(comment=f"subset of stage {stage}: {', '.join(methods)}, seeds {seeds}", methods=methods, seeds=seeds,
             variants=variants or [{"name": "default"}])
    with open(f"{work}/{name}.json.tmp", "w") as fh:
        json.dump(c, fh, indent=2)
    os.replace(f"{work}/{name}.json.tmp", f"{work}/{name}.json")
subset("a_fisher_fvs_s47", 5, ["fisher", "fvs"], [4, 5, 6, 7])
subset("b_random_s03", 3, ["random"], [0, 1, 2, 3])
subset("c_hybrid_s03", 3, ["hybrid"], [0, 1, 2, 3])
subset("d_saresgs_s47", 5, ["sa-resgs"], [4, 5, 6, 7])
subset("e_random_s47", 5, ["random"], [4, 5, 6, 7])
subset("f_stage4_plain", 4, ["fisher", "resgs", "fisher-logdet"], [0, 1, 2, 3],
       [{"name": "default", "methods": ["resgs", "fisher-logdet", "fisher"]},
        {"name": "replay-fisher", "methods": ["resgs"], "replay": "fisher"}])
subset("g_stage4_sahash", 4, ["sa-hash"], [0, 1, 2, 3])
subset("b2_logdet_s03", 4, ["fisher-logdet"], [0, 1, 2, 3])
EOF
ablate_share() {  # binary, config, out folder, shard; a failed job is reported and left for the next start
  if ! nice -n 19 "$1" ablate --config "$2" --out "$3" --shard "$4/2" >> "$work/shard$me.log" 2>&1; then
    echo "verdict2_remaining: $(basename "$2") (shard $4/2) had a failed job (see above); going on" >> "$work/shard$me.log"
  fi
}
run() {  # binary, config[, out folder]: this shard's share of the config
  ablate_share "$1" "$2" "${3:-results/verdict2}" "$me"
  touch "$work/done_$(basename "$2" .json)_$me"
}
# For binaries that take a lock per job (864af66, 5b76fc9): this shard's share, then the
# other shard's, so that the shard that finishes first takes the other's pending jobs instead
# of waiting idle at the next barrier (a job runs once whichever shard reaches it; a shard
# that meets a job held by the other waits for it to finish there).
run_locked() {
  ablate_share "$1" "$2" "${3:-results/verdict2}" "$me"
  ablate_share "$1" "$2" "${3:-results/verdict2}" "$other"
  touch "$work/done_$(basename "$2" .json)_$me"
}
# Waits until the other shard has finished config $1 in this run: its mark is there and no
# process of it is still on $1 or a config before it ($2...). Marks left by an earlier start
# of the other shard alone could let this one through while it catches up, hence the check
# of what it is running.
barrier() {
  local mark=$1
  shift
  while :; do
    local busy=0 c
    for c in "$mark" "$@"; do
      pgrep -f "ablate --config [^ ]*$c.json --out results/verdict2 --shard $other/2" > /dev/null && busy=1
    done
    [ -e "$work/done_${mark}_$other" ] && [ $busy = 0 ] && return
    sleep 20
  done
}
rm -f "$work"/done_*_"$me"
if [ -n "${PAPER:-}" ]; then run_locked "$PAPER" results/grid_paper_preset.json results/paper_preset; fi
run_locked "$old" "$work/a_fisher_fvs_s47.json"
run_locked "$old" "$work/b_random_s03.json"
# fisher-logdet (the D-optimal selector, the one stage-4 method that could change the
# target's answer) before the rest, so that neither shard waits idle at the barrier
run_locked "$old" "$work/b2_logdet_s03.json"
barrier b2_logdet_s03 a_fisher_fvs_s47 b_random_s03
run "$emb" results/grid_hash.json
run "$emb" "$work/c_hybrid_s03.json"
run "$emb" "$work/d_saresgs_s47.json"
run_locked "$old" "$work/e_random_s47.json"
run_locked "$old" "$work/f_stage4_plain.json"
barrier f_stage4_plain grid_hash c_hybrid_s03 d_saresgs_s47 e_random_s47
run "$emb" "$work/g_stage4_sahash.json"
echo "verdict2_remaining: shard $me done" >> "$work/shard$me.log"
