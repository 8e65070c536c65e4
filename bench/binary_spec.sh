# Sourced by the bench scripts. A binary argument is PATH, or ENV=VALUE:PATH to run that binary
# with one environment variable set (e.g. PENUMBRA_X=0:build/app/penumbra, a feature switched off).
# split_binary SPEC sets binary_env (an array: the assignment, or empty) and binary_path; run it as
#   env "${binary_env[@]}" [WRAPPER...] "$binary_path" ARGS...
split_binary() {
  binary_env=()
  binary_path=$1
  if [[ $1 == *=*:* ]]; then binary_env=("${1%%:*}"); binary_path=${1#*:}; fi
}
