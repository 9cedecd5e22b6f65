#!/usr/bin/env bash
# Wall time of the paper campaign at another commit and at this checkout, interleaved run by
# run so that both see the same machine load. Prints one line per run and the medians.
#   usage: bash bench/ab_campaign.sh REV [ROUNDS=5]
# The other commit is checked out in a temporary git worktree (removed at the end); both sides
# run `python3 -m palpate.cli sim --campaign paper --no-plots --json` from their own tree.
set -euo pipefail
rev=${1:?usage: bench/ab_campaign.sh REV [ROUNDS]}
rounds=${2:-5}
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'git -C "$here" worktree remove --force "$tmp/base" >/dev/null 2>&1 || true; rm -rf "$tmp"' EXIT
git -C "$here" worktree add --detach "$tmp/base" "$rev" >/dev/null 2>&1
for r in $(seq 1 "$rounds"); do
  for side in base head; do
    dir=$tmp/base
    [ "$side" = head ] && dir=$here
    (cd "$dir" && /usr/bin/time -o "$tmp/time" -f "%e" python3 -m palpate.cli sim \
      --campaign paper --no-plots --json --out "$tmp/out-$side" >"$tmp/$side.json" 2>/dev/null)
    campaign=$(python3 -c "import json,sys; print(round(json.load(open(sys.argv[1]))['wall_s'], 2))" "$tmp/$side.json")
    echo "$side run $r: command $(cat "$tmp/time") s, campaign $campaign s" | tee -a "$tmp/runs"
  done
done
python3 - "$tmp/runs" <<'PY'
import statistics, sys
runs = {"base": ([], []), "head": ([], [])}
for line in open(sys.argv[1]):
    side, _, _, _, cmd, _, _, camp, _ = line.split()
    runs[side][0].append(float(cmd)); runs[side][1].append(float(camp))
(bc, bm), (hc, hm) = runs["base"], runs["head"]
med = statistics.median
print(f"median command: base {med(bc):.2f} s, head {med(hc):.2f} s, ratio {med(hc) / med(bc):.2f}")
print(f"median campaign: base {med(bm):.2f} s, head {med(hm):.2f} s, ratio {med(hm) / med(bm):.2f}")
PY
