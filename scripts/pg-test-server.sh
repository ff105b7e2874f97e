#!/usr/bin/env bash
# A throw-away PostgreSQL server for the store tests (crates/gyrolab-store/tests): initdb in a
# temporary folder, pg_ctl on 127.0.0.1 with a free port (its unix socket in that folder), a
# password-protected role and database. Installs the Debian package `postgresql` when missing
# (announced on stderr). Run as root (CI) or as a user allowed to sudo.
#
#   source scripts/pg-test-server.sh start   # exports GYROLAB_TEST_PG_URL, stops itself at exit
#   bash scripts/pg-test-server.sh run CMD... # runs CMD with GYROLAB_TEST_PG_URL set, then stops
#
# `start` must be sourced (it sets a trap on EXIT of the calling shell that stops and removes the
# server); `stop` stops the one named in GYROLAB_TEST_PG_DIR.
set -euo pipefail

pg_bin() {
    local d
    for d in /usr/lib/postgresql/*/bin; do
        if [ -x "$d/initdb" ]; then
            echo "$d"
            return 0
        fi
    done
    return 1
}

as_root() {
    if [ "$(id -u)" = "0" ]; then "$@"; else sudo "$@"; fi
}

gyrolab_pg_start() {
    local bin dir port pw
    if ! bin=$(pg_bin); then
        echo "pg-test-server: installing postgresql (Debian package) for the store tests" >&2
        export DEBIAN_FRONTEND=noninteractive
        as_root apt-get update -qq >&2
        as_root apt-get install -y -qq --no-install-recommends postgresql >&2
        bin=$(pg_bin)
    fi
    dir=$(mktemp -d /tmp/gyrolab-pg.XXXXXX)
    chmod 755 "$dir"
    mkdir "$dir/data"
    as_root chown postgres "$dir" "$dir/data"
    port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    pw="gyrolab-test-$(od -An -N8 -tx8 /dev/urandom | tr -d ' ')"
    export GYROLAB_TEST_PG_DIR="$dir"
    (umask 077 && echo "$pw" >"$dir/pwfile")
    as_root chown postgres "$dir/pwfile"
    as_root runuser -u postgres -- "$bin/initdb" -D "$dir/data" -A scram-sha-256 --username=postgres \
        --pwfile="$dir/pwfile" >"$dir/initdb.log" 2>&1 || {
        echo "pg-test-server: initdb failed:" >&2
        cat "$dir/initdb.log" >&2
        return 1
    }
    rm -f "$dir/pwfile"
    as_root runuser -u postgres -- "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
        -o "-c listen_addresses=127.0.0.1 -p $port -k $dir -c fsync=off" start >/dev/null || {
        echo "pg-test-server: the server did not start:" >&2
        cat "$dir/server.log" >&2
        return 1
    }
    PGPASSWORD="$pw" psql -q -h 127.0.0.1 -p "$port" -U postgres -d postgres \
        -c "CREATE ROLE gyrolab LOGIN PASSWORD '$pw'" -c "CREATE DATABASE gyrolab OWNER gyrolab" \
        -c "CREATE ROLE gyrolab_app LOGIN PASSWORD '$pw'" >/dev/null
    export GYROLAB_TEST_PG_URL="postgres://gyrolab:$pw@127.0.0.1:$port/gyrolab"
    # A role with no privilege of its own: the least-privilege tests grant it SELECT and INSERT.
    export GYROLAB_TEST_PG_APP_URL="postgres://gyrolab_app:$pw@127.0.0.1:$port/gyrolab"
    echo "pg-test-server: PostgreSQL on 127.0.0.1:$port (folder $dir)" >&2
}

gyrolab_pg_stop() {
    local bin dir="${GYROLAB_TEST_PG_DIR:-}"
    if [ -z "$dir" ] || [ ! -d "$dir" ]; then
        return 0
    fi
    bin=$(pg_bin) || return 0
    as_root runuser -u postgres -- "$bin/pg_ctl" -D "$dir/data" -m immediate -w stop >/dev/null 2>&1 || true
    rm -rf "$dir"
    unset GYROLAB_TEST_PG_DIR GYROLAB_TEST_PG_URL GYROLAB_TEST_PG_APP_URL
}

case "${1:-}" in
    start)
        trap gyrolab_pg_stop EXIT
        gyrolab_pg_start
        ;;
    stop)
        gyrolab_pg_stop
        ;;
    run)
        shift
        trap gyrolab_pg_stop EXIT
        gyrolab_pg_start
        "$@"
        ;;
    *)
        echo "usage: source scripts/pg-test-server.sh start | bash scripts/pg-test-server.sh run CMD... | stop" >&2
        exit 2
        ;;
esac
