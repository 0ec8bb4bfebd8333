#!/usr/bin/env bash
# A throwaway PostgreSQL cluster for the store tests (ctest FIXTURES_SETUP / FIXTURES_CLEANUP).
#   postgres_fixture.sh start STATE_FILE   initdb + pg_ctl start on a Unix socket in a temp folder,
#                                          as an unprivileged user when run as root; writes the
#                                          libpq connection string to STATE_FILE, or
#                                          "unavailable: <reason>" (the tests then SKIP, saying so)
#   postgres_fixture.sh stop STATE_FILE    stops the cluster and removes its folder
set -u
action=$1
state=$2
bin=${IMUFIT_PG_BIN:-$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)}

unavailable() {
  echo "unavailable: $*" >"$state"
  echo "PostgreSQL tests will be skipped: $*"
  exit 0
}

as_owner() {
  if [[ $(id -u) == 0 ]]; then
    runuser -u nobody -- "$@"
  else
    "$@"
  fi
}

case $action in
  start)
    [[ -x $bin/initdb && -x $bin/pg_ctl ]] || unavailable "no initdb/pg_ctl (install Debian's postgresql)"
    dir=$(mktemp -d "${TMPDIR:-/tmp}/imufit_pg.XXXXXX") || unavailable "cannot make a temp folder"
    chmod 755 "$dir"
    [[ $(id -u) == 0 ]] && chown nobody "$dir"
    echo "$dir" >"$state.dir"
    as_owner "$bin/initdb" -D "$dir/data" -A trust -U imufit --no-sync >"$dir/initdb.log" 2>&1 ||
      unavailable "initdb failed: $(tail -n 1 "$dir/initdb.log")"
    as_owner "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
      -o "-k $dir -c listen_addresses= -c fsync=off -c max_connections=100" start >/dev/null 2>&1 ||
      unavailable "the server did not start: $(tail -n 1 "$dir/server.log")"
    echo "host=$dir dbname=postgres user=imufit" >"$state"
    echo "PostgreSQL test cluster on $dir"
    ;;
  stop)
    if [[ -f $state.dir ]]; then
      dir=$(cat "$state.dir")
      [[ -d $dir/data ]] && as_owner "$bin/pg_ctl" -D "$dir/data" -m immediate -w stop >/dev/null 2>&1
      rm -rf "$dir" "$state.dir"
    fi
    rm -f "$state"
    ;;
  *)
    echo "usage: $0 start|stop STATE_FILE" >&2
    exit 2
    ;;
esac
