#!/usr/bin/env bash
# Regenerates every file the code's declarations generate (`make regen`):
#   schemas/v1/{generate,synth,train,frames,graphify}-config.schema.json   --list-options --format schema
#   samples/{generate,train,frames}.json                           --print-config (the defaults)
#   docs/options.md (the sections after its title)                  --list-options --format md
#   samples/semantic-classes.json                                   nsg/core/semantic_classes.h, through _nsgraph
#   docs/metrics.md (the table of its "Metric list" section)        score --list-metrics
#   schemas/v1/score-report.schema.json (its four metric lists      score --list-metrics --format json
#     and its two count lists: a tile's counts, aggregate.sums)      score --list-counts
# --check writes them into a temporary copy and fails naming every file that differs
# (ctest repo/regen): a declaration changed without `make regen`.
# usage: scripts/regen.sh [--check] [BUILD]
set -euo pipefail
cd "$(dirname "$0")/.."
check=0
if [[ "${1:-}" == "--check" ]]; then check=1; shift; fi
build="${1:-build}"
nsgraph="$build/tools/nsgraph/nsgraph"
[[ -x "$nsgraph" ]] || { echo "regen: no $nsgraph (run make build first)" >&2; exit 2; }
out=.
if (( check )); then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
  mkdir -p "$out/schemas/v1" "$out/samples" "$out/docs"
fi
same() {  # same <committed> <generated>: equal bytes, or for .json equal JSON (a file's own layout is kept)
  [[ -f "$1" ]] || return 1
  cmp -s "$1" "$2" && return 0
  [[ "$1" == *.json ]] && /usr/bin/python3 -c 'import json, sys; sys.exit(json.load(open(sys.argv[1])) != json.load(open(sys.argv[2])))' "$1" "$2"
}
write() {  # write <file>: stdin to <out>/<file> via a temp name, unless the committed file says the same
  local dest="$out/$1"
  cat > "$dest.tmp.$$"
  if (( ! check )) && same "$1" "$dest.tmp.$$"; then rm -f "$dest.tmp.$$"; return; fi
  mv "$dest.tmp.$$" "$dest"
}

for command in generate synth train frames graphify; do
  "$nsgraph" "$command" --list-options --format schema | write "schemas/v1/$command-config.schema.json"
done
for command in generate train frames; do
  "$nsgraph" "$command" --print-config | write "samples/$command.json"
done
{
  sed -n '1,/^## `nsgraph generate` options$/p' docs/options.md | sed '$d'
  first=1
  for command in generate synth train frames graphify; do
    (( first )) || echo
    first=0
    "$nsgraph" "$command" --list-options --format md
  done
} | write docs/options.md
# The "Metric list" section of docs/metrics.md: its prose kept, its table (the section's
# lines that start with '|') replaced by what score --list-metrics prints.
"$nsgraph" score --list-metrics --format md > "$out/metric-list.tmp"
/usr/bin/python3 - docs/metrics.md "$out/metric-list.tmp" <<'PY' | write docs/metrics.md
import sys
lines = open(sys.argv[1], encoding="utf-8").read().split("\n")
table = open(sys.argv[2], encoding="utf-8").read().rstrip("\n").split("\n")
start = lines.index("## Metric list")
end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
body = [l for l in lines[start + 1:end] if not l.startswith("|")]
while body and body[-1] == "":
    body.pop()
sys.stdout.write("\n".join(lines[:start + 1] + body + [""] + table + [""] + lines[end:]))
PY
rm -f "$out/metric-list.tmp"
# The metric lists of schemas/v1/score-report.schema.json (a tile's metrics and the
# aggregate's mean, n_defined and n_undefined): their required names and properties written
# from score --list-metrics, each object keeping the $ref its values have (value or count).
"$nsgraph" score --list-metrics --format json > "$out/metric-table.tmp"
"$nsgraph" score --list-counts > "$out/count-names.tmp"
/usr/bin/python3 - schemas/v1/score-report.schema.json "$out/metric-table.tmp" "$out/count-names.tmp" <<'PY' | write schemas/v1/score-report.schema.json
import json, sys
schema = json.load(open(sys.argv[1], encoding="utf-8"))
names = [m["name"] for m in json.load(open(sys.argv[2], encoding="utf-8"))]
aggregate = schema["properties"]["aggregate"]["properties"]
for obj, ref in ((schema["definitions"]["tile"], "#/definitions/value"), (aggregate["mean"], "#/definitions/value"),
                 (aggregate["n_defined"], "#/definitions/count"), (aggregate["n_undefined"], "#/definitions/count")):
    # The metrics are the properties whose schema is the bare $ref; others (a tile's counts) stay after them.
    others = {k: v for k, v in obj["properties"].items() if v != {"$ref": ref}}
    obj["required"] = names + [k for k in obj["required"] if k in others]
    obj["properties"] = {**{name: {"$ref": ref} for name in names}, **others}
# A tile's counts and the aggregate's sums: exactly the count names, in their order.
counts = json.load(open(sys.argv[3], encoding="utf-8"))
for obj in (schema["definitions"]["tile"]["properties"]["counts"], aggregate["sums"]):
    obj["required"] = counts
    obj["properties"] = {name: {"$ref": "#/definitions/count"} for name in counts}
sys.stdout.write(json.dumps(schema, indent=2, ensure_ascii=False) + "\n")
PY
rm -f "$out/metric-table.tmp" "$out/count-names.tmp"
PYTHONPATH="$build/python" /usr/bin/python3 - <<'PY' | write samples/semantic-classes.json
import json
from nsgraph import SEMANTIC_CLASSES, SEMANTIC_VOID
rows = [json.dumps({"id": c["id"], "name": c["name"], "color": list(c["color"])}) for c in SEMANTIC_CLASSES]
print('{\n  "schema_version": "1",\n  "void_id": %d,\n  "classes": [\n    %s\n  ]\n}' % (SEMANTIC_VOID, ",\n    ".join(rows)))
PY

if (( check )); then
  status=0
  for f in schemas/v1/{generate,synth,train,frames}-config.schema.json samples/{generate,train,frames}.json \
           docs/options.md docs/metrics.md samples/semantic-classes.json schemas/v1/score-report.schema.json; do
    if ! same "$f" "$out/$f"; then
      echo "regen: $f differs from what the declarations give; run \`make regen\`" >&2
      diff -u "$f" "$out/$f" | head -20 >&2 || true
      status=1
    fi
  done
  exit $status
fi
echo "regen: schemas, samples and docs/options.md written"
