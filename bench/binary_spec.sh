# Sourced by the bench scripts: binary specs, and two helpers on numbers they time.
# A binary argument is PATH, or ENV=VALUE:PATH to run that binary
# with one environment variable set (e.g. PENUMBRA_X=0:build/app/penumbra, a feature switched off).
# split_binary SPEC sets binary_env (an array: the assignment, or empty) and binary_path; run it as
#   env "${binary_env[@]}" [WRAPPER...] "$binary_path" ARGS...
split_binary() {
  binary_env=()
  binary_path=$1
  if [[ $1 == *=*:* ]]; then binary_env=("${1%%:*}"); binary_path=${1#*:}; fi
}

# The median of the numbers on standard input, one per line.
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

# The render phase's seconds from `penumbra render`'s summary line on standard input
# ("..., 64.0 spp (min 64, max 64), 0.900 s (+0.345 s build), ..."); nothing if there is none.
render_phase_seconds() { sed -n 's/.*spp (min [0-9]*, max [0-9]*), \([0-9.]*\) s.*/\1/p'; }
