#!/usr/bin/env bash
# Speed against a baseline commit, built beside this tree and run in the same sitting.
#
#   bash scripts/perf.sh table   [BASE]   step time against Gaussians, resolution and threads,
#                                         this tree and BASE alternated; writes
#                                         results/perf/table.jsonl and docs/RESULTS.md's tables
#   bash scripts/perf.sh regress [BASE]   bench step 512x384/20k, this tree and BASE
#                                         alternated (5 rounds); exits 1, loudly, when
#                                         this tree is more than 10% slower
#   bash scripts/perf.sh accept  [BASE]   issue 26's acceptance measures, this tree and BASE
#                                         alternated: bench step 20k and 100k, the residual
#                                         ratio and bench fisher (3 rounds), saresgs train on
#                                         room360 512x384 (2 rounds), the main job's command
#                                         (2 rounds: new, base, base, new); writes
#                                         results/perf/accept.jsonl and prints a table
#                                         (about 10 minutes on the AMD EPYC VM)
#   bash scripts/perf.sh startup [BASE]   how long `saresgs --version` takes from exec to
#                                         exit, this tree and BASE alternated (31 runs each,
#                                         medians), and the shared libraries each loads at
#                                         start; writes results/perf/startup.json
#
# BASE defaults to b0ae65c for `table` and `accept` (the code issue 26 is judged against) and to
# HEAD~1 for `regress`. It is built once into build-perf/<sha> (Release, the CLI only;
# a few minutes on two cores; PERF_BASE_BIN=path uses a binary built before). This tree
# must already be built (scripts/build.sh).
# Nothing here is a test: times depend on the machine and its load, which each output
# names. Not run by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
case "$mode" in
  table|accept) base_ref=${2:-b0ae65c} ;;
  startup) base_ref=${2:-8437562} ;;
  regress) base_ref=${2:-HEAD~1} ;;
  *) echo "usage: bash scripts/perf.sh table|regress|accept|startup [BASE-COMMIT]" >&2; exit 2 ;;
esac
new=./build/apps/saresgs
[ -x "$new" ] || { echo "perf.sh: $new is missing: run bash scripts/build.sh first" >&2; exit 2; }
sha=$(git rev-parse --short=7 "$base_ref^{commit}") || { echo "perf.sh: no commit $base_ref" >&2; exit 2; }
dir=build-perf/$sha
base=${PERF_BASE_BIN:-$dir/build/apps/saresgs}
if [ ! -x "$base" ]; then
  echo "perf.sh: building $sha into $dir (once)" >&2
  rm -rf "$dir"
  mkdir -p "$dir"
  git archive "$sha" | tar -x -C "$dir"
  cmake -S "$dir" -B "$dir/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSARESGS_BUILD_TESTS=OFF >/dev/null
  cmake --build "$dir/build" --parallel "$(nproc)" --target saresgs >/dev/null
fi
[ -x "$base" ] || { echo "perf.sh: the build of $sha did not produce $base" >&2; exit 1; }
load() { cut -d' ' -f1-3 /proc/loadavg; }
machine="$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores"

if [ "$mode" = regress ]; then
  args="bench step --width 512 --height 384 --gaussians 20000 --steps 21"
  echo "regress: this tree ($(git rev-parse --short=7 HEAD)$(git diff --quiet || echo '+changes')) vs $sha; $machine; load $(load)" >&2
  out=$(for r in 1 2 3 4 5; do
    for who in new base; do
      bin=$new; [ $who = base ] && bin=$base
      echo "$who $($bin $args | tail -1)"
    done
  done)
  /usr/bin/python3 - "$out" <<'EOF'
import json, statistics, sys
runs = {"new": [], "base": []}
for line in sys.argv[1].splitlines():
    who, js = line.split(" ", 1)
    runs[who].append(json.loads(js)["median_ms"])
n, b = statistics.median(runs["new"]), statistics.median(runs["base"])
print(f"bench step 512x384/20k: this tree {n:.2f} ms, base {b:.2f} ms (medians of 5 alternated runs), ratio {n / b:.3f}")
print("  this tree:", " ".join(f"{x:.1f}" for x in runs["new"]), "| base:", " ".join(f"{x:.1f}" for x in runs["base"]))
if n > 1.10 * b:
    print(f"REGRESSION: this tree's step is {100 * (n / b - 1):.0f}% slower than the base (limit 10%)", file=sys.stderr)
    sys.exit(1)
EOF
  echo "load after: $(load)" >&2
  exit 0
fi

if [ "$mode" = startup ]; then
  mkdir -p results/perf
  /usr/bin/python3 - "$new" "$base" "$(git rev-parse --short=7 HEAD)$(git diff --quiet || echo '+changes')" "$sha" "$machine" <<'EOF'
import json, os, statistics, subprocess, sys, time
new, base, head, base_sha, machine = sys.argv[1:6]
load = lambda: " ".join(open("/proc/loadavg").read().split()[:3])
def libraries(binary):  # what the loader maps at start (what ldd lists)
    out = subprocess.run([binary], env={**os.environ, "LD_TRACE_LOADED_OBJECTS": "1"}, capture_output=True, text=True).stdout
    return sum(1 for line in out.splitlines() if line.strip())
times = {"new": [], "base": []}
load_before = load()
for _ in range(31):
    for who, binary in (("new", new), ("base", base)):
        t0 = time.perf_counter()
        subprocess.run([binary, "--version"], stdout=subprocess.DEVNULL, check=True)
        times[who].append(time.perf_counter() - t0)
med = {who: statistics.median(v) * 1000 for who, v in times.items()}
record = {"command": "saresgs --version", "this_tree": head, "base": base_sha, "machine": machine,
          "load_before": load_before, "load_after": load(), "runs_each": 31,
          "median_ms": med, "ratio": med["new"] / med["base"],
          "libraries_at_start": {"new": libraries(new), "base": libraries(base)}}
tmp = "results/perf/startup.json.tmp"
with open(tmp, "w") as f:
    json.dump(record, f, indent=1)
    f.write("\n")
os.replace(tmp, "results/perf/startup.json")
print(f"saresgs --version: this tree {head} {med['new']:.1f} ms, {base_sha} {med['base']:.1f} ms (medians of 31 alternated), "
      f"ratio {record['ratio']:.3f}; libraries at start {record['libraries_at_start']['new']} vs "
      f"{record['libraries_at_start']['base']}; {machine}; load {load_before} before")
EOF
  exit 0
fi

if [ "$mode" = accept ]; then
  # The main job's command for each binary (the base may predate --no-plain-refit, which
  # scripts/main.sh passes), on the built-in scene; the train bench's scene at 512x384.
  [ -f out/builtin/manifest.json ] || $new scene --layout room360 --out out/builtin >/dev/null
  [ -f out/bench_room360_512x384/manifest.json ] || $new bench train --width 512 --height 384 --iterations 1 >/dev/null
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  mkdir -p results/perf
  tmp=results/perf/accept.jsonl.tmp
  : > "$tmp"
  echo "accept: this tree ($(git rev-parse --short=7 HEAD)$(git diff --quiet || echo '+changes')) vs $sha; $machine; load $(load)" >&2
  rec() { echo "{\"who\": \"$1\", \"what\": \"$2\", \"load\": \"$(load)\", \"result\": $3}" >> "$tmp"; echo "  $1 $2" >&2; }
  timed() {  # the wall time of a command in seconds (its output to $work/log)
    local t0 t1
    t0=$(date +%s.%N)
    if ! "$@" > "$work/log" 2>&1; then
      echo "perf.sh: failed: $*" >&2
      tail -n 20 "$work/log" >&2
      return 1
    fi
    t1=$(date +%s.%N)
    /usr/bin/python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$t0" "$t1"
  }
  for r in 1 2 3; do
    for who in new base; do
      bin=$new; [ $who = base ] && bin=$base
      rec $who step20k "$($bin bench step --width 512 --height 384 --gaussians 20000 --steps 21 | tail -1)"
      rec $who step100k "$($bin bench step --width 512 --height 384 --gaussians 100000 --steps 11 | tail -1)"
      rec $who residual "$($bin bench step --width 512 --height 384 --gaussians 20000 --steps 21 --residual | tail -1)"
      rec $who fisher "$($bin bench fisher | tail -1)"
    done
  done
  for r in 1 2; do
    for who in new base; do
      bin=$new; [ $who = base ] && bin=$base
      sec=$(timed $bin train --dataset out/bench_room360_512x384 --iterations 300 --threads 2 --out "$work/train_$who")
      # Beside the command's wall time: the training's own seconds (results.json) and, for a
      # binary that decodes the images before training (since 5627716; b0ae65c decodes each
      # one inside the step that first reads it), that decoding's milliseconds from the log.
      loop=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['train_seconds_this_run'])" "$work/train_$who/results.json")
      decode_ms=$(sed -n 's/^decoded [0-9]* images in \([0-9]*\) ms$/\1/p' "$work/log")
      rec $who train "{\"seconds\": $sec, \"train_seconds\": $loop, \"decode_ms\": ${decode_ms:-0}, \"iterations\": 300}"
    done
  done
  # Two rounds in the order new, base, base, new: one run each swung by 10 % with the VM's
  # drift within a sitting, and this order gives each binary the same mean position.
  k=0
  for who in new base base new; do
    bin=$new; [ $who = base ] && bin=$base
    k=$((k + 1))
    extra=""
    # The help is read whole before the test: under pipefail, `grep -q` leaving at its first
    # match could end the writer by SIGPIPE and make the test false (the main job would then
    # run with the plain refit, a second 1600-iteration fit that scripts/main.sh leaves out).
    help=$($bin active --help)
    if grep -q -- --no-plain-refit <<< "$help"; then extra=--no-plain-refit; fi
    sec=$(timed $bin active --dataset out/builtin --method sa-resgs --preset quick --seed 0 $extra --out "$work/main_$k")
    psnr=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['final_fit']['psnr'])" "$work/main_$k/results.json")
    rec $who main "{\"seconds\": $sec, \"final_fit_psnr\": $psnr, \"lines\": $(wc -l < "$work/log"), \"args\": \"$extra\"}"
  done
  mv "$tmp" results/perf/accept.jsonl
  /usr/bin/python3 - "$sha" "$(git rev-parse --short=7 HEAD)" "$machine" <<'EOF'
import json, sys
base_sha, head, machine = sys.argv[1:4]
rows = [json.loads(l) for l in open("results/perf/accept.jsonl")]
def vals(who, what, f):
    return [f(r["result"]) for r in rows if r["who"] == who and r["what"] == what]
nan = float("nan")
measures = [
    ("bench step 512x384/20k, median ms", "step20k", lambda d: d["median_ms"], "<= 0.6x"),
    ("bench step 100k, median ms", "step100k", lambda d: d["median_ms"], "<= 0.62x"),
    ("residual / plain step (20k)", "residual", lambda d: d.get("residual_to_plain_ratio", nan), "<= 1.25"),
    ("bench fisher / backward", "fisher", lambda d: d["fisher_to_backward_ratio"], "<= 1.0"),
    ("heap allocations per step", "step20k", lambda d: d.get("allocations_per_step", nan), "0 after the first"),
    ("saresgs train room360 512x384, it/s of the training (its loop and the image decoding)", "train",
     lambda d: d["iterations"] / (d["train_seconds"] + d["decode_ms"] / 1000) if "train_seconds" in d else nan, ">= 2.17x"),
    ("saresgs train room360 512x384, it/s of the whole command", "train", lambda d: d["iterations"] / d["seconds"],
     "(the loading, the evaluation of 19 test views and the writing too)"),
    ("main job, s", "main", lambda d: d["seconds"], "<= 0.64x"),
    ("main job final-fit PSNR, dB", "main", lambda d: d["final_fit_psnr"], ">= 25.7"),
    ("main job lines of output", "main", lambda d: d["lines"], "<= 200"),
]
print(f"this tree {head} against {base_sha}; {machine}; load {rows[0]['load']} at the start, {rows[-1]['load']} at the end")
print("| measure | this tree | base | acceptance |")
print("|---|---:|---:|---|")
fmt = lambda xs: ", ".join(f"{x:.2f}" for x in xs) if xs else "(not measured)"
for name, what, f, acc in measures:
    print(f"| {name} | {fmt(vals('new', what, f))} | {fmt(vals('base', what, f))} | {acc} |")
EOF
  echo "wrote results/perf/accept.jsonl; load after $(load)" >&2
  exit 0
fi

# table: configurations, each run alternately by this tree and the base.
mkdir -p results/perf
tmp=results/perf/table.jsonl.tmp
: > "$tmp"
configs=(
  "--width 512 --height 384 --gaussians 10000 --threads 1" "--width 512 --height 384 --gaussians 10000 --threads 2"
  "--width 512 --height 384 --gaussians 20000 --threads 1" "--width 512 --height 384 --gaussians 20000 --threads 2"
  "--width 512 --height 384 --gaussians 100000 --threads 1" "--width 512 --height 384 --gaussians 100000 --threads 2"
  "--width 512 --height 384 --gaussians 500000 --threads 1 --steps 7" "--width 512 --height 384 --gaussians 500000 --threads 2 --steps 7"
  "--width 256 --height 192 --gaussians 20000 --threads 1" "--width 256 --height 192 --gaussians 20000 --threads 2"
  "--width 1024 --height 768 --gaussians 20000 --threads 1 --steps 11" "--width 1024 --height 768 --gaussians 20000 --threads 2 --steps 11"
)
echo "table: this tree ($(git rev-parse --short=7 HEAD)) vs $sha; $machine; load $(load)" >&2
load_before=$(load)
for c in "${configs[@]}"; do
  for who in new base; do
    bin=$new; [ $who = base ] && bin=$base
    line=$($bin bench step $c | tail -1)
    echo "{\"who\": \"$who\", \"args\": \"$c\", \"load\": \"$(load)\", \"result\": $line}" >> "$tmp"
    echo "  $who $c" >&2
  done
done
mv "$tmp" results/perf/table.jsonl
/usr/bin/python3 scripts/experiments/results_doc.py  # its speed section reads results/perf/table.jsonl
echo "wrote results/perf/table.jsonl (this tree $(git rev-parse --short=7 HEAD) against $sha, load $load_before before) and docs/RESULTS.md; load after $(load)" >&2
