#!/bin/sh
# Regenerates dlca_pooled_df.csv: DLCA's 2D fractal dimension at 1% fill on periodic lattices of
# 256^2 to 2048^2, each an ensemble of the dlca binary (`--seeds`, `--gyration`) ended at 30
# clusters, from ensemble.json: the fit pooled over every member's clusters (jackknife error
# over members) and the mean of the members' own fits. Usage: sh docs/results/dlca_pooled_df.sh
# [DLCA_BINARY] (default target/release/dlca); the members stay in target/dlca-pooled-df/.
set -eu
DLCA=${1:-target/release/dlca}
RUNS=target/dlca-pooled-df
OUT=docs/results/dlca_pooled_df.csv
mkdir -p "$RUNS"
echo "size,fill,target_clusters,fit_min_size,seeds,pooled_d,pooled_stderr,pooled_fit_stderr,pooled_clusters,per_member_mean,per_member_stderr,per_member_fits,command" > "$OUT.tmp"
for spec in 256:64 512:64 1024:64 2048:16; do
    L=${spec%%:*}
    S=${spec##*:}
    ARGS="--size $L --fill 0.01 --target-clusters 30 --gyration --seeds 1..=$S --jobs 1 -qq"
    "$DLCA" $ARGS --out "$RUNS/$L" --overwrite
    python3 - "$RUNS/$L/ensemble.json" "$L" "$S" "dlca $ARGS --out DIR" >> "$OUT.tmp" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))
p = e["pooled"]["fractal_dimension"]
f = lambda v: "" if v is None else f"{v:.4f}"
print(",".join([sys.argv[2], "0.01", "30", str(p["fit_min_size"]), sys.argv[3],
                f(p["fractal_dimension"]), f(p["fractal_dimension_stderr"]), f(p["fit_stderr"]),
                str(p["fit_clusters"]), f(p["per_member_mean"]), f(p["per_member_stderr"]),
                str(p["per_member_fits"]), '"' + sys.argv[4] + '"']))
PY
done
mv "$OUT.tmp" "$OUT"
