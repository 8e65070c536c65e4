#!/usr/bin/env bash
# A throwaway PostgreSQL 15 cluster for the farm tests (tests/farm/), from Debian's packages:
# initdb in a folder, served on 127.0.0.1:PORT with trust authentication, as a non-root user
# (PostgreSQL refuses to run as root: `runuser -u postgres` when we are root).
#
#   scripts/farm-postgres.sh start DIR PORT   # prints the store URL
#   scripts/farm-postgres.sh stop DIR [MODE]  # MODE: fast (default) or immediate (a crash)
#   scripts/farm-postgres.sh restart DIR      # stop and start again on the same port
set -euo pipefail
cmd="$1"
dir="$2"
bin="$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)"
if [ -z "$bin" ] || [ ! -x "$bin/initdb" ]; then
  echo "farm-postgres.sh: no PostgreSQL server (apt-get install postgresql)" >&2
  exit 3
fi
as_pg() {
  if [ "$(id -u)" = 0 ]; then runuser -u postgres -- "$@"; else "$@"; fi
}
case "$cmd" in
  start)
    port="$3"
    mkdir -p "$dir"
    [ "$(id -u)" = 0 ] && chown postgres: "$dir"
    if [ ! -f "$dir/data/PG_VERSION" ]; then
      as_pg "$bin/initdb" -D "$dir/data" -A trust -U postgres --no-sync >"$dir/initdb.log" 2>&1
    fi
    echo "$port" >"$dir/port"
    as_pg "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
      -o "-p $port -k $dir -c listen_addresses=127.0.0.1 -c max_connections=200 -c fsync=on" \
      start >/dev/null
    echo "postgresql://postgres@127.0.0.1:$port/postgres"
    ;;
  stop)
    as_pg "$bin/pg_ctl" -D "$dir/data" -m "${3:-fast}" -w -t 60 stop >/dev/null
    ;;
  restart)
    port="$(cat "$dir/port")"
    as_pg "$bin/pg_ctl" -D "$dir/data" -m fast -w -t 60 stop >/dev/null
    as_pg "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
      -o "-p $port -k $dir -c listen_addresses=127.0.0.1 -c max_connections=200" start >/dev/null
    ;;
  *)
    echo "usage: $0 start DIR PORT | stop DIR [fast|immediate] | restart DIR" >&2
    exit 2
    ;;
esac
