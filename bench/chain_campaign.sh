#!/usr/bin/env bash
# The campaign of the chain test (tests/cli_chain_test.cc, issue 29 item 9): ChainTest.Campaign on
# the seeds FIRST..LAST, each a drawn lot, plan, schedule, station and limits run through the whole
# chain, then a table: per check, how many times it ran and failed (and on which seeds), and the
# ratio of the fit's 1-sigma to plan check's prediction per schedule (min, median, max, the share
# outside the 10 % the suite asserts).
#
#   bench/chain_campaign.sh BUILD_DIR FIRST LAST [JOBS]
#
# JOBS processes run seed ranges side by side (default 1). The raw lines stay in
# BUILD_DIR/chain_campaign/report.txt, each failure's message in report.txt's `detail=`, and each
# failed seed's folder under the system's temporary folder (named by the test), to look at.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 BUILD_DIR FIRST LAST [JOBS]" >&2
  exit 2
fi
build=$1 first=$2 last=$3 jobs=${4:-1}
program=$build/tests/cli_chain_test
[ -x "$program" ] || { echo "$0: $program not built (ninja -C $build cli_chain_test)" >&2; exit 2; }
out=$build/chain_campaign
rm -rf "$out"
mkdir -p "$out"
report=$out/report.txt
: >"$report"
count=$((last - first + 1))
per=$(((count + jobs - 1) / jobs))
pids=()
for ((j = 0; j < jobs; ++j)); do
  lo=$((first + j * per))
  hi=$((lo + per - 1))
  ((hi > last)) && hi=$last
  ((lo > hi)) && continue
  IMUFIT_CHAIN_SEEDS=$lo-$hi IMUFIT_CHAIN_REPORT=$out/report-$j.txt \
    "$program" --gtest_filter=ChainTest.Campaign >"$out/log-$j.txt" 2>&1 &
  pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid" || true; done
cat "$out"/report-*.txt >"$report"

echo "chain campaign: seeds $first..$last ($count seeds)"
awk '
  /^check / {
    for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
    runs[f["check"]]++
    if (f["ok"] == 0) {
      failed[f["check"]]++
      if (index(" " seeds[f["check"]] " ", " " f["seed"] " ") == 0) seeds[f["check"]] = seeds[f["check"]] " " f["seed"]
    }
  }
  END {
    printf "%-16s %6s %7s  %s\n", "check", "runs", "failed", "seeds failing"
    for (c in runs) printf "%-16s %6d %7d  %s\n", c, runs[c], failed[c], seeds[c]
  }' "$report" | sort
echo
echo "fit 1-sigma / plan check 1-sigma, per schedule (every 25 degC figure of every unit):"
printf "%-12s %6s %8s %8s %8s %14s\n" schedule figures min median max "outside 10 %"
for schedule in $(awk '/^ratio /{for(i=2;i<=NF;++i){split($i,kv,"=");if(kv[1]=="schedule")print kv[2]}}' "$report" | sort -u) all; do
  awk -v s="$schedule" '/^ratio /{for(i=2;i<=NF;++i){split($i,kv,"=");f[kv[1]]=kv[2]} if(s=="all"||f["schedule"]==s)print f["ratio"]}' \
    "$report" | sort -g | awk -v s="$schedule" '
      { r[NR] = $1; if ($1 < 0.9 || $1 > 1.1) out++ }
      END { if (NR) printf "%-12s %6d %8.3f %8.3f %8.3f %8d (%3.0f%%)\n", s, NR, r[1], r[int((NR + 1) / 2)], r[NR], out, 100 * out / NR }'
done
