#!/usr/bin/env python3
"""Summarises scripts/bench_compare.sh: for each sweep, each measured row's time is the
minimum over the rounds of its median frame time (median_ms), for the before and the after
build; prints every row's after/before ratio, the geometric mean per sweep, and whether the
error columns (PSNR, mean and max absolute error) are the same in both."""
import csv
import math
import sys

KEYS = {
    "billboards": ["series", "param", "value", "width", "height"],
    "impostors": ["series", "path", "policy", "tolerance_deg", "frame", "impostor"],
    "scaling": ["series", "mode", "triangles", "width", "height"],
    "warp": ["series", "value", "method", "references", "width", "height"],
    "lightfield": ["series", "method", "eye_class", "eye", "uv", "st", "codewords", "tile",
                   "triangles", "width", "height"],
}
ERRORS = ["psnr_db", "mean_abs", "mae", "mae_mean", "mae_max", "worst_mae"]


def load(path, keys):
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[tuple(r[k] for k in keys)] = r
    return rows


def main():
    out, before, after, rounds = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    for sweep in sys.argv[5:]:
        keys = KEYS[sweep]
        best = {}
        errs = {before: {}, after: {}}
        for c in (before, after):
            for r in range(1, rounds + 1):
                for k, row in load(f"{out}/{c}-r{r}/{sweep}.csv", keys).items():
                    t = float(row.get("median_ms") or 0)
                    if t > 0:
                        best.setdefault(c, {})
                        best[c][k] = min(best[c].get(k, math.inf), t)
                    errs[c][k] = tuple(row.get(e, "") for e in ERRORS)
        common = sorted(set(best[before]) & set(best[after]))
        ratios = []
        print(f"{sweep}: {len(common)} rows (min over {rounds} rounds of each row's median ms)")
        for k in common:
            b, a = best[before][k], best[after][k]
            ratios.append(a / b)
            print(f"  {' '.join(k):<60} before {b:9.3f}  after {a:9.3f}  ratio {a / b:6.3f}")
        gm = math.exp(sum(math.log(x) for x in ratios) / len(ratios)) if ratios else float("nan")
        # Rows where both builds measured an error (a column may be newer than a build).
        rows_both = sorted(set(errs[before]) & set(errs[after]))
        both = [k for k in rows_both
                if any(x and y for x, y in zip(errs[before][k], errs[after][k]))]
        differ = [k for k in both
                  if any(x != y for x, y in zip(errs[before][k], errs[after][k]) if x and y)]
        same = len(both) - len(differ)
        print(f"{sweep}: geometric mean ratio after/before {gm:.3f}; "
              f"median ratio {sorted(ratios)[len(ratios) // 2]:.3f}; "
              f"error columns equal in {same} of the {len(both)} rows both builds measured")
        for k in differ:
            print(f"  errors differ: {' '.join(k)}: before {errs[before][k]} after {errs[after][k]}")


if __name__ == "__main__":
    main()
