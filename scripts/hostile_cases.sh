#!/usr/bin/env bash
# Runs a fixed list of malformed invocations against a nystrom binary and counts, per class, how many are
# refused correctly: exit status 2, stderr exactly one line starting "nystrom: error: ", printable ASCII and at
# most 300 characters, no file created in the working folder or in TMPDIR, within 20 s.
#
#   bash scripts/hostile_cases.sh [-v] PATH/TO/nystrom
#
# -v lists every case that was not refused correctly, with the reason. The binary is started directly (argv
# as given, no shell), each case in a fresh working folder with a private TMPDIR. Classes: numbers (syntax,
# non-finite, signs, range), counts (overflow, work budgets), specs (method specifications and method files),
# paths (output and input files), injection (shell and gnuplot metacharacters in names), other (the command
# line itself). Exit status: 0 when every case is refused correctly, 1 otherwise.
set -uo pipefail
verbose=0
if [ "${1:-}" = -v ]; then
  verbose=1
  shift
fi
if [ $# -ne 1 ] || [ ! -x "$1" ]; then
  echo "usage: bash scripts/hostile_cases.sh [-v] PATH/TO/nystrom" >&2
  exit 2
fi
bin=$(realpath "$1")
work=$(mktemp -d "${TMPDIR:-/tmp}/nystrom-hostile-cases.XXXXXX")
trap 'rm -rf "$work"' EXIT
data=$work/data
mkdir -p "$data/adir"
printf 'name \x01\x02\xff\xfe\n\x7f\x80 kick 1\n\x1b[31m' >"$data/junk.bin"
{
  echo "name long"
  echo "order 1"
  for _ in $(seq 5000); do printf 'drift 1/5000\nkick 1/5000\n'; done
} >"$data/long.method"
seq5000=$(seq -s, 5000)
seq201=$(seq -s, 201)
adj5000=$(printf 'adjoint:%.0s' $(seq 5000))
fast=(--methods FR --force-evals 1e3:1e3:1)

declare -A total ok
classes=(numbers counts specs paths injection other)
for c in "${classes[@]}"; do total[$c]=0 ok[$c]=0; done

# case CLASS ARG...: runs `nystrom ARG...` and checks the refusal.
case_() {
  local class=$1
  shift
  local dir=$work/case
  rm -rf "$dir"
  mkdir -p "$dir/run" "$dir/tmp"
  local rc=0
  (cd "$dir/run" && TMPDIR=$dir/tmp NYSTROM_PROGRESS=0 timeout -s KILL 20 "$bin" "$@" \
    </dev/null >"$dir/out" 2>"$dir/err")
  rc=$?
  local why=""
  local lines
  lines=$(wc -l <"$dir/err")
  if [ $rc -eq 137 ]; then
    why="no end within 20 s"
  elif [ $rc -ne 2 ]; then
    why="exit status $rc"
  elif [ "$lines" -ne 1 ] || [ -n "$(tail -c1 "$dir/err")" ]; then
    why="$lines lines on stderr"
  elif ! head -c 16 "$dir/err" | grep -q '^nystrom: error: $'; then
    why="no 'nystrom: error:' prefix"
  elif LC_ALL=C grep -q '[^ -~]' <(head -c -1 "$dir/err"); then
    why="non-printable bytes"
  elif [ "$(wc -c <"$dir/err")" -gt 301 ]; then
    why="a line of $(wc -c <"$dir/err") characters"
  elif [ -n "$(find "$dir/run" "$dir/tmp" -mindepth 1 | head -3)" ]; then
    why="files left: $(find "$dir/run" "$dir/tmp" -mindepth 1 -printf '%P ' | head -c 200)"
  fi
  total[$class]=$((total[$class] + 1))
  if [ -z "$why" ]; then
    ok[$class]=$((ok[$class] + 1))
  elif [ $verbose = 1 ]; then
    local shown
    shown=$(printf '%q ' "$@" | cut -c1-100)
    echo "  [$class] $shown: $why: $(head -c 120 "$dir/err" | tr '\n' ' ' | LC_ALL=C tr -c '[:print:]' '?')"
  fi
  rm -rf "$dir"
}

# numbers: empty, non-finite, trailing characters, signs, fractions for counts, out of range
for v in '' nan inf -inf 0.5x ' 0.5' 0x1p-1 1e999 1 -0.1 '0.5 ' '+' . e5 0.5e; do
  case_ numbers run --method FR --ecc "$v"
done
for v in 0 -5 1.5 1e3 99999999999999999999 '' 0x10 ' 7'; do
  case_ numbers run --method FR --steps-per-period "$v"
done
case_ numbers run --method FR --periods 0
case_ numbers run --problem nbody --method LF --eps2 -5
case_ numbers run --problem nbody --method LF --eps2 nan
case_ numbers run --problem nbody --method LF --h 0
case_ numbers run --problem nbody --method LF --h -1
case_ numbers run --problem nbody --method LF --h 1e-400
case_ numbers run --problem nbody --method LF --n 0
case_ numbers run --problem nbody --method LF --n 1
case_ numbers run --problem nbody --method LF --n 2000000
case_ numbers run --problem nbody --method LF --seed -1
case_ numbers run --problem nbody --method LF --steps -3
case_ numbers run --method DP12-adaptive --tol 0
case_ numbers run --method DP12-adaptive --tol inf
case_ numbers run --method DP12-adaptive --tol -1e-9
case_ numbers sweep "${fast[@]}" --t-end -1
case_ numbers sweep "${fast[@]}" --ecc 1.5
case_ numbers sweep "${fast[@]}" --problem nbody --eps2 -1
case_ numbers sweep "${fast[@]}" --problem nbody --n 1
case_ numbers localerr --eps -1 --methods LF --n 10
case_ numbers localerr --threads -1 --methods LF --n 10
case_ numbers localerr --tol inf --methods LF --n 10
case_ numbers localerr --h 0:1:2 --methods LF --n 10
case_ numbers cputime --steps 0 --n 10
case_ numbers cputime --repeats 0 --n 10
case_ numbers cputime --n 1
case_ numbers cputime --h -1 --n 10
case_ numbers cputime --eps -1 --n 10
case_ numbers bch --method FR --tolerance inf
case_ numbers bch --method FR --tolerance -1
case_ numbers bch --method FR --tolerance nan
case_ numbers bch --method FR --degree 13
case_ numbers bch --method FR --bits 10
case_ numbers bench-peers --periods 0
case_ numbers bench-peers --ecc 1
case_ numbers discover --starts 0
case_ numbers discover --digits 1
case_ numbers discover --threads -3
case_ numbers coeffs FR --digits 0
case_ numbers coeffs FR --digits -1

# counts: overflow in conversions, absurd work
case_ counts sweep --methods FR --force-evals 1e20:1e20:1
case_ counts sweep --methods FR --force-evals 1e3:1e4:0
case_ counts sweep --methods FR --force-evals 1e3:1e4:2.5
case_ counts sweep --methods FR --force-evals 1e3:1e4:99999999999999999999
case_ counts sweep --methods FR --force-evals 1e13:1e13:1 --periods 100000
case_ counts sweep --methods FR --force-evals 1e308:1e308:1
case_ counts run --method FR --steps-per-period 1000000000 --periods 1000000000
case_ counts run --method M8 --precision mpfr:256 --steps-per-period 1000000000 --periods 1000
case_ counts run --problem nbody --method RKNb6 --n 1000000 --steps 1000
case_ counts run --problem nbody --method LF --n 100000 --steps 100000000
case_ counts localerr --duration 1e308 --methods LF --n 10
case_ counts localerr --duration 1e300 --h 1e-300:1e-300:1 --methods LF --n 10
case_ counts cputime --n 1000000 --steps 1000 --methods RKNa14
case_ counts bench-peers --periods 1e12
case_ counts bench-peers --periods 1000000000000
case_ counts coeffs mpe --seq "$seq5000"
case_ counts coeffs mpe --n 5000 --sum 100000000
case_ counts coeffs mpe --seq 99999999999999999999
case_ counts bch --method "file:$data/long.method" --degree 12
case_ counts discover --starts 99999999999999999999
case_ counts run --method FR --output-times 0:1:99999999999
case_ counts run --method FR --output-times 0:1:0

# specs: method specifications and method files
case_ specs coeffs "${adj5000}bogus"
case_ specs run --method "${adj5000}${adj5000}bogus"
case_ specs bch --method "${adj5000}M8"
case_ specs coeffs m99999999999999999999
case_ specs coeffs m99999999999999999999-adaptive
case_ specs coeffs mpe:99999999999999999999
case_ specs coeffs mpe
case_ specs coeffs mpe --seq 1,1
case_ specs coeffs mpe --seq 0,1
case_ specs coeffs mpe --seq ' 1,2'
case_ specs coeffs mpe --seq 1,2,
case_ specs coeffs mpe --order 3
case_ specs coeffs triplejump:99999
case_ specs coeffs M3
case_ specs coeffs M0
case_ specs coeffs mpe:
case_ specs coeffs mpe:1,,2
case_ specs coeffs adjoint:
case_ specs run --method "mpe:$seq201"
case_ specs run --method ''
case_ specs run --method $'\x01\x02\xff\xfe\x1b[31m'
case_ specs run --method bogus
case_ specs run --method "file:$data/junk.bin"
case_ specs run --method "file:$data/none/x.method"
case_ specs run --method "file:$data/adir"
case_ specs run --method file:
case_ specs run --method FR --precision bogus
case_ specs run --method FR --problem bogus
case_ specs run --method FR --precision mpfr:1
case_ specs run --method FR --precision mpfr:99999999999999999999
case_ specs run --method FR --tol 1e-9
case_ specs run --method FR --events bogus
case_ specs run --method FR --restart "$data/junk.bin"
case_ specs sweep --methods '' --force-evals 1e3:1e4:2
case_ specs sweep --methods FR,,M4 --force-evals 1e3:1e4:2
case_ specs sweep --methods bogus --force-evals 1e3:1e4:2
case_ specs sweep "${fast[@]}" --error bogus
case_ specs sweep "${fast[@]}" --problem nbody --error precession
case_ specs sweep --methods DP12-adaptive --tols 1e-6:1e-9
case_ specs localerr --gbs-sequence bogus --methods LF --n 10
case_ specs localerr --methods bogus --n 10
case_ specs bch
case_ specs bch --method bogus
case_ specs reproduce bogus
case_ specs reproduce chin-fig1 --quad bogus

# paths: output and input files
case_ paths demo --out-dir ''
case_ paths demo --out-dir "$data/none/folder"
case_ paths sweep "${fast[@]}" --csv ''
case_ paths sweep "${fast[@]}" --plot ''
case_ paths sweep "${fast[@]}" --csv "$data/adir"
case_ paths sweep "${fast[@]}" --plot "$data/adir"
case_ paths sweep "${fast[@]}" --csv "$data/none/x.csv"
case_ paths sweep "${fast[@]}" --plot "$data/none/x.png"
case_ paths sweep "${fast[@]}" --csv /proc/version
case_ paths sweep "${fast[@]}" --csv /dev/full
case_ paths sweep "${fast[@]}" --csv .
case_ paths sweep "${fast[@]}" --csv ..
case_ paths sweep "${fast[@]}" --csv /
case_ paths bench-peers --quick --out ''
case_ paths bench-peers --quick --out "$data/junk.bin/x"
case_ paths reproduce all --out-dir ''
case_ paths reproduce chin-fig1 --quick --out-dir "$data/junk.bin/d"
case_ paths run --problem nbody --method LF --ic "$data/junk.bin"
case_ paths run --problem nbody --method LF --ic "$data/none"
case_ paths run --problem nbody --method LF --ic ''
case_ paths run --problem nbody --method LF --ic "$data/adir"
case_ paths run --problem nbody --method LF --ic /dev/null
case_ paths run --method FR --checkpoint "$data/adir" --checkpoint-at 1
case_ paths run --method FR --checkpoint '' --checkpoint-at 1
case_ paths run --method FR --restart "$data/none"
case_ paths run --method FR --restart "$data/adir"

# injection: shell and gnuplot metacharacters in names that must be refused, and nothing executed
case_ injection run --method 'FR; touch PWNED'
case_ injection run --method '$(touch PWNED)'
case_ injection run --method '`touch PWNED`'
case_ injection run --method $'FR\ntouch PWNED'
case_ injection run --method 'file:|touch PWNED'
case_ injection run --method FR --precision 'double; touch PWNED'
case_ injection run --method FR --problem $'kepler\nsystem "touch PWNED"'
case_ injection sweep "${fast[@]}" --plot "$data/none/a"$'\nsystem \'touch PWNED\'\nb.png'
case_ injection sweep "${fast[@]}" --plot "$data/none/x'; system \"touch PWNED\"; '.png"
case_ injection sweep "${fast[@]}" --csv "$data/none/\$(touch PWNED).csv"
case_ injection sweep --methods "FR,\`touch PWNED\`" --force-evals 1e3:1e3:1 --plot p.png
case_ injection sweep --methods $'FR,a\nsystem "touch PWNED"' --force-evals 1e3:1e3:1 --plot p.png
case_ injection coeffs '$(touch PWNED)'
case_ injection bch --method "FR'; system 'touch PWNED"
case_ injection reproduce '$(touch PWNED)'
case_ injection demo --out-dir "$data/none/"$'\nsystem "touch PWNED"'

# other: the command line itself
case_ other
case_ other bogus
case_ other run --bogus-option
case_ other methods extra
case_ other run --method
case_ other $'\xff\xfe'
case_ other run --method FR --method M4 --ecc
case_ other --bogus
case_ other run --method FR --checkpoint c.txt
case_ other run --method FR --checkpoint-at 1
case_ other run --method FR --output-times 1:0:3
case_ other run --method FR --output-times a:b:c
case_ other run --problem nbody --method LF --output-times 0:1:3

status=0
all=0 good=0
for c in "${classes[@]}"; do
  printf '%-10s %4d of %4d refused correctly\n' "$c" "${ok[$c]}" "${total[$c]}"
  all=$((all + total[$c]))
  good=$((good + ok[$c]))
  [ "${ok[$c]}" -eq "${total[$c]}" ] || status=1
done
printf '%-10s %4d of %4d refused correctly\n' all "$good" "$all"
exit $status
