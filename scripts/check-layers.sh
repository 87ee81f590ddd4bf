#!/usr/bin/env bash
# Checks that the headers of include/nystrom/ point one way (docs/architecture.md, "The layers"): a header
# includes headers of its own directory and of directories of a lower layer, never of a higher one or of
# another directory of the same layer; and that the library, the tool, the Python module and the benchmarks
# point one way too (below). Prints each offending inclusion; exits 1 if there is one.
set -euo pipefail
cd "$(dirname "$0")/.."

# The layers, from the bottom up; directories on one line form one layer.
layers=(
  "core"
  "problems"
  "methods"
  "engines"
  "operators"
  "solve quantum planetary velocity stochastic"
  "analysis diagnostics"
)
declare -A rank
for i in "${!layers[@]}"; do
  for d in ${layers[$i]}; do rank[$d]=$i; done
done

status=0
for dir in include/nystrom/*/; do
  layer=$(basename "$dir")
  if [[ -z "${rank[$layer]+x}" ]]; then
    echo "check-layers: include/nystrom/$layer/ is in no layer (add it to scripts/check-layers.sh)"
    status=1
    continue
  fi
  while IFS=: read -r file line text; do
    target=$(sed -n 's|.*#include "nystrom/\([a-z_]*\)/.*|\1|p' <<<"$text")
    [[ -z "$target" || "$target" == "$layer" ]] && continue
    if [[ -z "${rank[$target]+x}" ]] || ((rank[$target] >= rank[$layer])); then
      echo "$file:$line: $layer includes $target (${text})"
      status=1
    fi
  done < <(grep -rn --include='*.hpp' --include='*.ipp' '#include "nystrom/' "$dir" || true)
done
# Above the library: the public headers include nothing of the tool, the tests or the benchmarks (paper
# reproduction and method search live in src/experiments/); the tool and the Python module include nothing of
# bench/ or tests/; the benchmarks nothing of tests/.
while IFS=: read -r file line text; do
  echo "$file:$line: a public header includes a file outside include/nystrom/ (${text})"
  status=1
done < <(grep -rn --include='*.hpp' '#include "' include/nystrom | grep -v '#include "nystrom/' || true)
while IFS=: read -r file line text; do
  echo "$file:$line: includes a file of bench/ or tests/ (${text})"
  status=1
done < <(grep -rn --include='*.cpp' --include='*.hpp' -E '#include "(\.\./)*(bench|tests)/|#include "peers/' src python || true)
while IFS=: read -r file line text; do
  echo "$file:$line: a benchmark includes a file of tests/ (${text})"
  status=1
done < <(grep -rn --include='*.cpp' --include='*.hpp' -E '#include "(\.\./)*tests/' bench || true)
if ((status != 0)); then
  echo "check-layers: inclusions against the layer order (docs/architecture.md)"
fi
exit $status
