# Sourced by the bench scripts: `best N COMMAND...` prints the best wall time of N runs of
# COMMAND in seconds (its output discarded; its stderr shown and the script stopped when it
# fails). Needs DATA (the bench data folder) set.
best() {
    local runs=$1 b="" t0 t1 s
    shift
    for _ in $(seq "$runs"); do
        t0=$(date +%s%N)
        "$@" >/dev/null 2>"$DATA/best_err.txt" || { cat "$DATA/best_err.txt" >&2; exit 1; }
        t1=$(date +%s%N)
        s=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.4f", (b - a) / 1e9}')
        if [ -z "$b" ] || awk -v a="$s" -v c="$b" 'BEGIN{exit !(a<c)}'; then b=$s; fi
    done
    echo "$b"
}
