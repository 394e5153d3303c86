#!/usr/bin/env python3
"""docs/errors.md's rows of requests scanner serve refuses (scripts/errors-table.sh runs it
against a server it started on loopback): | what | request | status and error |."""
import http.client
import json
import os
import sys
import time

PORT = int(sys.argv[1])
SCANS = sys.argv[2]  # the server's scans folder: a link is planted in it
JSON = {"Content-Type": "application/json"}


def ask(method, path, headers, body=None):
    """The answer as "status error", once the server listens."""
    for _ in range(100):
        try:
            c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=10)
            c.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
            for k, v in {"Host": f"127.0.0.1:{PORT}", **headers}.items():
                c.putheader(k, v)
            data = body.encode() if body is not None else None
            if data is not None:
                c.putheader("Content-Length", str(len(data)))
            c.endheaders(data)
            r = c.getresponse()
            text = r.read().decode(errors="replace")
            try:
                text = json.loads(text).get("error", text)
            except ValueError:
                pass
            return f"{r.status} {text}".replace("|", "\\|")
        except ConnectionRefusedError:
            time.sleep(0.1)
    return "no answer"


ROWS = [
    ("another site's page starts a scan", "POST /api/scans, Origin: http://evil.example",
     "POST", "/api/scans", {**JSON, "Origin": "http://evil.example"}, "{}"),
    ("CORS pre-flight", "OPTIONS /api/scans, Origin: http://evil.example", "OPTIONS",
     "/api/scans", {"Origin": "http://evil.example", "Access-Control-Request-Method": "POST"},
     None),
    ("DNS rebinding", "GET /api/status, Host: evil.example", "GET", "/api/status",
     {"Host": "evil.example"}, None),
    ("a cross-site request", "GET /api/scans, Sec-Fetch-Site: cross-site", "GET", "/api/scans",
     {"Sec-Fetch-Site": "cross-site"}, None),
    ("the camera by GET (an img on any page)", "GET /api/snapshot.png", "GET",
     "/api/snapshot.png", {}, None),
    ("the rig without the session key", "POST /api/scans {}", "POST", "/api/scans", JSON, "{}"),
    ("deeply nested JSON", "POST /api/login, 800 x [ then 800 x ]", "POST", "/api/login", JSON,
     "[" * 800 + "]" * 800),
    ("a tar option as a scan id", "GET /api/scans/-x/archive.tar", "GET",
     "/api/scans/-x/archive.tar", {}, None),
    ("no such scan's archive", "GET /api/scans/2000-01-01_000000/archive.tar", "GET",
     "/api/scans/2000-01-01_000000/archive.tar", {}, None),
]
os.symlink("/etc", os.path.join(SCANS, "evil"))
ask("GET", "/api/status", {})  # it listens
c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=10)
c.request("GET", "/api/session", headers={"Host": f"127.0.0.1:{PORT}"})
KEY = {**JSON, "X-Scanner-Key": json.loads(c.getresponse().read())["key"]}
ROWS += [
    ("a linked scan folder", "GET /api/scans/evil/files/passwd (evil -> /etc)", "GET",
     "/api/scans/evil/files/passwd", {}, None),
    ("junk after the JSON body", 'POST /api/scans {"profile": "one"} junk (with the key)', "POST",
     "/api/scans", KEY, '{"profile": "one"} junk'),
    ("JSON 33 levels deep", "POST /api/scans, 33 x [ inside {} (with the key)", "POST",
     "/api/scans", KEY, '{"a": ' + "[" * 33 + "]" * 33 + "}"),
    ("another site's Origin with the key", "POST /api/scans/X/stop, Origin: http://evil.example",
     "POST", "/api/scans/x/stop", {**KEY, "Origin": "http://evil.example"}, "{}"),
]
for what, shown, method, path, headers, body in ROWS:
    print(f"| {what} | `{shown}` | {ask(method, path, headers, body)} |")
