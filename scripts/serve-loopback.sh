# serve_loopback LOG COMMAND...: starts COMMAND --listen 127.0.0.1:PORT on a port found free and
# waits until it listens; sets $port and $web (its PID). Sourced by scripts/errors-table.sh and
# tests/cli.sh. A port free a moment ago may be taken by the time the server binds it (CI met
# one: the server exited "in use" and the requests found nothing listening), so a server that
# exits is started again on another port; one that has not listened within 30 s is reported.
serve_listens() { /usr/bin/python3 -c "import socket; socket.create_connection(('127.0.0.1', $1), 1)" 2>/dev/null; }
serve_loopback() {
    serve_log=$1
    shift
    for serve_try in 1 2 3 4 5; do
        port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
        "$@" --listen "127.0.0.1:$port" >"$serve_log" 2>&1 &
        web=$!
        serve_i=0
        while kill -0 "$web" 2>/dev/null && ! serve_listens "$port" && [ $serve_i -lt 300 ]; do
            sleep 0.1
            serve_i=$((serve_i + 1))
        done
        kill -0 "$web" 2>/dev/null && break
        wait "$web" 2>/dev/null
    done
    serve_listens "$port" || { echo "the server did not listen:" >&2; cat "$serve_log" >&2; return 1; }
}
