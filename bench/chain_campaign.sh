#!/usr/bin/env bash
# The campaign of the chain test (tests/cli_chain_test.cc, issue 29 item 9): ChainTest.Campaign on
# the seeds FIRST..LAST, each a drawn lot, plan, schedule, station and limits run through the whole
# chain, then a table: per check, how many times it ran and failed (and on which seeds), and the
# ratio of the fit's 1-sigma to plan check's prediction per schedule (min, median, max, the share
# outside the 10 % the suite asserts).
#
#   bench/chain_campaign.sh BUILD_DIR FIRST LAST [JOBS]
#   bench/chain_campaign.sh --table REPORT        (the table of a campaign's report.txt again)
#
# JOBS processes run seed ranges side by side (default 1). The raw lines stay in
# BUILD_DIR/chain_campaign/report.txt, each failure's message in report.txt's `detail=`, and each
# failed seed's folder under the system's temporary folder (named by the test), to look at.
set -euo pipefail

# The table of a report: lines "check seed=S check=C ok=0|1 [detail=...]" and
# "ratio seed=S schedule=K unit=U figure=F ratio=R white=W chi2=X".
table() {
  awk '
    /^check / {
      split($2, sd, "="); split($3, ck, "="); split($4, o, "=")
      runs[ck[2]]++
      if (o[2] == 0) {
        failed[ck[2]]++
        if (index(" " seeds[ck[2]] " ", " " sd[2] " ") == 0) seeds[ck[2]] = seeds[ck[2]] " " sd[2]
      }
    }
    END {
      printf "%-22s %6s %7s  %s\n", "check", "runs", "failed", "seeds failing"
      for (c in runs) printf "%-22s %6d %7d  %s\n", c, runs[c], failed[c], seeds[c]
    }' "$1"
  for part in ratio white; do
    echo
    if [ $part = ratio ]; then
      echo "fit 1-sigma as reported / plan check 1-sigma, per schedule (every 25 degC figure of every unit):"
    else
      echo "its white-noise part (divided by sqrt(max(1, reduced chi-square))) / plan check 1-sigma:"
    fi
    printf "%-12s %7s %8s %8s %8s %8s %14s\n" schedule figures min median max sd "outside 10 %"
    for schedule in $(awk '/^ratio /{split($3, k, "="); print k[2]}' "$1" | sort -u) all; do
      awk -v s="$schedule" -v part="$part" '/^ratio /{
          split($3, k, "="); split($6, r, "="); split($7, w, "=")
          if (s == "all" || k[2] == s) print (part == "ratio" ? r[2] : w[2])
        }' "$1" | sort -g | awk -v s="$schedule" '
        { r[NR] = $1; sum += $1; sq += $1 * $1; if ($1 < 0.9 || $1 > 1.1) out++ }
        END {
          if (NR) printf "%-12s %7d %8.3f %8.3f %8.3f %8.3f %7d (%3.0f%%)\n", s, NR, r[1], r[int((NR + 1) / 2)],
                         r[NR], sqrt(sq / NR - (sum / NR)^2), out, 100 * out / NR
        }'
    done
  done
}

if [ "${1:-}" = --table ]; then
  table "$2"
  exit 0
fi
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
table "$report"
