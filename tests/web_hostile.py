#!/usr/bin/env python3
"""scanner serve against a hostile tester (issue 28): another site's page, DNS rebinding, GETs
that would use the rig, deep JSON, a token-free server on the network, slow and silent clients,
planted pipes and links, guessed names, resume with other settings, a failed scan remembered.
Every request goes over real HTTP on loopback. Prints cmocka-style lines for tests/run.sh.
    python3 tests/web_hostile.py BUILD"""
import http.client
import json
import os
import shutil
import socket
import subprocess
import sys
import threading
import time

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCANNER = os.path.join(ROOT, BUILD, "scanner")
OUT = os.path.join(ROOT, BUILD, "web-hostile")
passed = failed = 0


def check(ok, name, detail=""):
    global passed, failed
    if ok:
        passed += 1
        print(f"[       OK ] {name}")
    else:
        failed += 1
        print(f"[  FAILED  ] {name}")
        if detail:
            print("    " + str(detail).replace("\n", "\n    "))
    sys.stdout.flush()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def request(port, method, path, headers=None, body=None, timeout=20, host=None):
    """(status, headers dict lower-cased, body bytes); the path goes out as written."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    h = {"Host": host or f"127.0.0.1:{port}"}
    h.update(headers or {})
    if isinstance(body, str):
        body = body.encode()
    c.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    for k, v in h.items():
        c.putheader(k, v)
    if body is not None:
        c.putheader("Content-Length", str(len(body)))
    c.endheaders(body)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, {k.lower(): v for k, v in r.getheaders()}, data


class Server:
    def __init__(self, args):
        self.log = open(os.path.join(OUT, f"serve-{len(os.listdir(OUT))}.log"), "w+")
        self.proc = subprocess.Popen([SCANNER, "serve"] + args, stdout=subprocess.PIPE,
                                     stderr=self.log, text=True)
        line = self.proc.stdout.readline()
        if "http://" not in line:
            raise RuntimeError(f"serve did not start: {line} {self.text()}")

    def text(self):
        self.log.flush()
        with open(self.log.name) as f:
            return f.read()

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        return self.proc.wait(timeout=120)


def start_refused(args):
    """rc and messages of a serve that must refuse to start."""
    p = subprocess.run([SCANNER, "serve"] + args, capture_output=True, text=True, timeout=30)
    return p.returncode, p.stderr


def write_configs():
    """fast: a sphere in 4 views at 320 x 240 (about a second); long: the same in 100 views."""
    calib = open(os.path.join(ROOT, "config/sim-calib.ini")).read()
    for a, b in [("fx_px = 2400", "fx_px = 600"), ("fy_px = 2400", "fy_px = 600"),
                 ("cx_px = 639.5", "cx_px = 159.5"), ("cy_px = 479.5", "cy_px = 119.5"),
                 ("width = 1280", "width = 320"), ("height = 960", "height = 240")]:
        calib = calib.replace(a, b, 1)
    with open(os.path.join(OUT, "calib.ini"), "w") as f:
        f.write(calib)
    base = ("[camera]\nbackend = sim\nwidth = 320\nheight = 240\nexposure_us = 10000\n"
            "[lights]\ncount = 0\n[scan]\nviews = {views}\ncalibration = {out}/calib.ini\n"
            "[output]\ndir = {out}/scans\n[turntable]\ntransport = tcp\nhost = 127.0.0.1\n"
            "port = 0\n[registration]\nicp = 0\n[sim]\nobject = sphere\n")
    for name, views in [("fast", 4), ("long", 100)]:
        with open(os.path.join(OUT, f"{name}.ini"), "w") as f:
            f.write(base.format(views=views, out=OUT))
    # cut: the fast scan in a volume 40 mm tall that may not grow, which the sphere rises above
    with open(os.path.join(OUT, "cut.ini"), "w") as f:
        f.write(base.format(views=4, out=OUT) + "[fusion]\ntop_mm = 40\nfit_volume = 0\n")
    # asked: a calibration at the simulated rig whose person waits to be told to go on
    with open(os.path.join(OUT, "asked.ini"), "w") as f:
        f.write(base.format(views=4, out=OUT).replace("[sim]\n", "[sim]\nperson = asked\n"))


def wait_state(port, sid, states, timeout=120, key=None):
    until = time.time() + timeout
    while time.time() < until:
        st, _, body = request(port, "GET", f"/api/scans/{sid}")
        if st == 200 and json.loads(body)["state"] in states:
            return json.loads(body)
        time.sleep(0.2)
    return None


def admission(port, scans):
    """Another site, another Host name, GETs that would use the rig, a missing key."""
    js = {"Content-Type": "application/json"}
    st, h, _ = request(port, "OPTIONS", "/api/scans", {
        "Origin": "http://evil.example", "Access-Control-Request-Method": "POST",
        "Access-Control-Request-Headers": "content-type"})
    check(st >= 400 and "access-control-allow-origin" not in h
          and "access-control-allow-methods" not in h,
          f"a CORS pre-flight from another site is never answered yes ({st})", h)
    st, h, _ = request(port, "GET", "/api/status", {"Origin": "http://evil.example"})
    check(st == 403 and "access-control-allow-origin" not in h,
          f"a request with another site's Origin is refused ({st})")
    st, _, body = request(port, "GET", "/api/status", host="evil.example:80")
    check(st == 403, f"a DNS-rebinding Host name is refused on a token-free server ({st})", body)
    st, _, _ = request(port, "GET", "/api/status", host=f"localhost:{port}")
    check(st == 200, f"the loopback names are answered (localhost: {st})")
    st, _, _ = request(port, "GET", "/api/scans", {"Sec-Fetch-Site": "cross-site"})
    check(st == 403, f"a cross-site fetch (Sec-Fetch-Site) is refused ({st})")
    st, _, _ = request(port, "GET", "/api/snapshot.png")
    check(st == 405, f"GET /api/snapshot.png (an <img> on any page) does not use the rig ({st})")
    st, _, _ = request(port, "GET", "/api/selftest")
    check(st == 405, f"nor does GET /api/selftest ({st})")
    st, _, _ = request(port, "POST", "/api/snapshot.png", js, "{}")
    check(st == 403, f"POST /api/snapshot.png without the session key is refused ({st})")
    st, _, body = request(port, "POST", "/api/scans", js, "{}")
    check(st == 403, f"POST /api/scans without the session key is refused ({st})", body)
    st, _, body = request(port, "POST", "/api/scans", {**js, "X-Scanner-Key": "0" * 32}, "{}")
    check(st == 403, f"and with a wrong key ({st})")
    st, _, body = request(port, "GET", "/api/session", {"Sec-Fetch-Site": "same-origin"})
    key = json.loads(body)["key"] if st == 200 else ""
    check(st == 200 and len(key) == 32, "the page's own request gets the session key")
    st, _, body = request(port, "GET", "/api/scans")
    check(st == 200 and json.loads(body)["scans"] == [], "no scan was started by any of them")
    deep = "[" * 800 + "]" * 800
    st, _, _ = request(port, "POST", "/api/login", js, deep)
    st2, _, _ = request(port, "GET", "/api/status")
    check(st == 400 and st2 == 200, f"800-deep JSON is refused and the server lives ({st}, {st2})")
    k = {**js, "X-Scanner-Key": key}
    st, _, _ = request(port, "POST", "/api/scans", k, '{"profile": "fast"} junk')
    check(st == 400, f"trailing junk after the JSON body is refused ({st})")
    st, _, _ = request(port, "POST", "/api/scans", k, '{"a": ' + "[" * 33 + "]" * 33 + "}")
    check(st == 400, f"JSON nested beyond 32 levels is refused ({st})")
    return key


def dos_and_stop(port, key, srv):
    """A scan running; 100 slowloris sockets and 16 progress streams that never read; status and
    Stop must still be answered at once."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    st, _, body = request(port, "POST", "/api/scans", js, '{"profile": "long"}')
    check(st == 200, f"a scan starts with the session key ({st})", body)
    sid = json.loads(body)["id"]
    until = time.time() + 60
    while time.time() < until and json.loads(request(port, "GET", f"/api/scans/{sid}")[2])[
            "views_done"] < 1:
        time.sleep(0.1)
    slow = []
    for _ in range(100):
        s = socket.create_connection(("127.0.0.1", port))
        s.sendall(b"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never finished
        slow.append(s)
    streams, refused = [], 0
    for _ in range(16):
        s = socket.create_connection(("127.0.0.1", port))
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
        s.sendall(f"GET /api/scans/{sid}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
        streams.append(s)  # never read
    time.sleep(1.0)
    t0 = time.time()
    st, _, body = request(port, "GET", "/api/status", timeout=10)
    t_status = time.time() - t0
    check(st == 200 and json.loads(body)["scanning"] and t_status < 3,
          f"status is answered during a scan beside 100 slow sockets and 16 silent streams "
          f"({t_status * 1000:.0f} ms)")
    t0 = time.time()
    st, _, body = request(port, "POST", f"/api/scans/{sid}/stop", js, "{}", timeout=10)
    t_stop = time.time() - t0
    check(st == 200 and t_stop < 3, f"so is Stop ({st}, {t_stop * 1000:.0f} ms)", body)
    st, _, _ = request(port, "GET", f"/api/scans/{sid}/events", timeout=10)
    check(st == 503, f"progress streams beyond 8 are refused, not queued ({st})")
    for s in slow + streams:
        s.close()
    state = wait_state(port, sid, ("stopped",))
    check(state is not None and 1 <= state["views_done"] < 100,
          f"the scan stopped with its finished views kept ({state and state['views_done']})")
    return sid


def resume_cases(port, key, sid, scans):
    """Resume picks the profile that takes views as the scan did, refuses any other; a scan
    that fails writing mesh.stl is failed, with its error, also after a restart."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    st, _, body = request(port, "POST", f"/api/scans/{sid}/resume", js, '{"profile": "fast"}')
    state = wait_state(port, sid, ("failed", "stopped", "finished")) if st == 200 else None
    check(state is not None and state["state"] == "failed" and "[scan] views" in state["error"]
          and not os.path.exists(os.path.join(scans, sid, "view_099")),
          "a resume with a profile of other settings is refused, naming the key",
          state or body)
    os.makedirs(os.path.join(scans, sid, "mesh.stl", "in-the-way"))
    st, _, body = request(port, "POST", f"/api/scans/{sid}/resume", js, "{}")
    state = wait_state(port, sid, ("failed", "finished"), timeout=180) if st == 200 else None
    check(state is not None and state["state"] == "failed" and state["views_done"] == 100
          and os.path.exists(os.path.join(scans, sid, "mesh.ply")),
          "a resume without a profile takes the scan's own ('long'); failing at mesh.stl, it is "
          "failed, not finished", state or body)
    return state["error"] if state else ""


def concurrent_thumbs(port, sid):
    """Thumbnails drawn in parallel (the report's reader is reentrant, no lock): each the same
    as when drawn alone."""
    paths = [f"/api/scans/{sid}/thumbs/{v}/{k}.png" for v in (0, 1) for k in ("raw", "colour",
                                                                             "reasons")]
    alone = {p: request(port, "GET", p) for p in paths}
    together, threads = {}, []
    for n in range(3):
        for p in paths:
            t = threading.Thread(target=lambda p=p, n=n: together.__setitem__(
                (p, n), request(port, "GET", p)))
            threads.append(t)
            t.start()
    for t in threads:
        t.join()
    same = all(together[(p, n)][0] == 200 and together[(p, n)][2] == alone[p][2]
               for p in paths for n in range(3))
    check(same and all(alone[p][0] == 200 for p in paths),
          f"18 thumbnails drawn at once are each the one drawn alone ({len(together)})")


def fifo_cases(port, sid, scans):
    view = os.path.join(scans, sid, "view_000")
    for name in os.listdir(view):
        if name.startswith("frame_"):
            os.unlink(os.path.join(view, name))
            os.mkfifo(os.path.join(view, name))
    t0 = time.time()
    codes = [request(port, "GET", f"/api/scans/{sid}/thumbs/0/{k}.png", timeout=15)[0]
             for k in ("raw", "colour", "reasons")]
    check(time.time() - t0 < 10 and codes[0] == 404,
          f"a named pipe planted as a frame does not block the thumbnails ({codes})")
    st, _, _ = request(port, "GET", f"/api/scans/{sid}/files/view_000/frame_00.ppm.zst")
    check(st == 404, f"nor is it served as a file ({st})")
    fifo = os.path.join(scans, sid, "summary.ini")
    os.mkfifo(fifo)
    try:
        p = subprocess.run([SCANNER, "report", os.path.join(scans, sid)], capture_output=True,
                           text=True, timeout=60)
        check(p.returncode == 0, "scanner report passes over a planted pipe (summary.ini)",
              p.stderr[-600:])
    except subprocess.TimeoutExpired:
        check(False, "scanner report passes over a planted pipe (it hung)")
    os.unlink(fifo)
    try:
        p = subprocess.run([SCANNER, "process", os.path.join(scans, sid), "--out",
                            os.path.join(OUT, "fifo-process")], capture_output=True, text=True,
                           timeout=60)
        check(p.returncode != 0 and "not a regular file" in p.stderr,
              "scanner process refuses a planted pipe instead of hanging", p.stderr[-600:])
    except subprocess.TimeoutExpired:
        check(False, "scanner process refuses a planted pipe instead of hanging (it hung)")


def path_cases(port, key, scans, sid):
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    os.symlink("/etc", os.path.join(scans, "evil"))
    st, _, body = request(port, "GET", "/api/scans/evil/files/passwd")
    check(st in (403, 404) and b"root:" not in body, f"a linked scan folder serves nothing ({st})")
    st, _, body = request(port, "GET", "/api/scans/evil/archive.tar")
    check(st == 404 and b"root:" not in body, f"nor archives anything ({st})")
    st, _, body = request(port, "GET", "/api/scans/-x/archive.tar")
    check(st == 404, f"an id that reads like an option of tar's is no scan ({st})")
    st, _, body = request(port, "GET", "/api/scans/2000-01-01_000000/archive.tar")
    check(st == 404, f"a nonexistent scan's archive is 404, not an empty tar ({st})")
    st, _, body = request(port, "POST", "/api/scans/evil/resume", js, "{}")
    check(st in (404, 409), f"a linked folder cannot be resumed ({st})")
    # 700 old folders, each a scan (a config.ini), that sort before the real ones
    cfg = os.path.join(scans, sid, "config.ini")
    for i in range(700):
        d = os.path.join(scans, f"2000-01-01_{i:06d}")
        os.mkdir(d)
        shutil.copy(cfg, d)
    st, _, body = request(port, "GET", "/api/scans", timeout=60)
    ids = [s["id"] for s in json.loads(body)["scans"]] if st == 200 else []
    check(len(ids) == 701 and ids[0] == sid,
          f"the scan list sorts every folder, the newest first ({len(ids)})")
    for i in range(700):
        shutil.rmtree(os.path.join(scans, f"2000-01-01_{i:06d}"))


def manage_cases(port, key, scans):
    """Scans to manage (issue 32): a label, checked; a delete that needs the key, refuses the
    running scan, removes the folder and never follows a link planted in it."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    st, _, body = request(port, "POST", "/api/scans", js, '{"profile": "fast"}')
    gone = json.loads(body)["id"] if st == 200 else ""
    state = wait_state(port, gone, ("finished", "failed")) if st == 200 else None
    check(state is not None and state["state"] == "finished", "a scan to manage is made", body)
    check(state is not None and state.get("warnings") == [] and state.get("warning_count") == 0,
          "a scan of an object inside the volume has no warning", state)
    lbl = f"/api/scans/{gone}/label"
    st, _, _ = request(port, "POST", lbl, {"Content-Type": "application/json"}, '{"label": "x"}')
    check(st == 403, f"a label without the session key is refused ({st})")
    bad = ['{"label": "two\\nlines"}', '{"label": "' + "x" * 101 + '"}', '{"label": 7}', "{}",
           '{"label": "bell\\u0007"}']
    sts = [request(port, "POST", lbl, js, b)[0] for b in bad]
    check(sts == [400] * len(bad), f"labels of two lines, 101 bytes, a number, none, a control "
          f"character are refused ({sts})")
    st, _, _ = request(port, "POST", lbl, js, json.dumps({"label": "Vase, front – 2nd try"}))
    got = json.loads(request(port, "GET", f"/api/scans/{gone}")[2]).get("label")
    listed = [x.get("label") for x in json.loads(request(port, "GET", "/api/scans")[2])["scans"]
              if x["id"] == gone]
    check(st == 200 and got == "Vase, front – 2nd try" and listed == [got],
          f"a label is kept and listed ({st}, {got!r})")
    st, _, _ = request(port, "POST", "/api/scans/no-such-scan/label", js, '{"label": "a"}')
    st2, _, _ = request(port, "POST", "/api/scans/..%2f..%2fetc/label", js, '{"label": "a"}')
    check(st == 404 and st2 in (403, 404), f"no label for a scan that is not there ({st}, {st2})")
    outside = os.path.join(OUT, "outside.txt")
    with open(outside, "w") as f:
        f.write("not the scanner's")
    os.symlink(outside, os.path.join(scans, gone, "planted-link"))
    os.symlink(OUT, os.path.join(scans, gone, "view_000", "planted-dir"))
    dele = f"/api/scans/{gone}/delete"
    st, _, _ = request(port, "POST", dele, {"Content-Type": "application/json"}, "{}")
    st2, _, _ = request(port, "POST", dele, {**js, "Origin": "http://evil.example"}, "{}")
    st3, _, _ = request(port, "GET", dele)
    check(st == 403 and st2 == 403 and st3 == 404 and os.path.isdir(os.path.join(scans, gone)),
          f"a delete without the key, from another site or by GET does nothing ({st}, {st2}, "
          f"{st3})")
    st, _, body = request(port, "POST", dele, js, "{}")
    st2, _, _ = request(port, "GET", f"/api/scans/{gone}")
    ids = [x["id"] for x in json.loads(request(port, "GET", "/api/scans")[2])["scans"]]
    check(st == 200 and st2 == 404 and gone not in ids and not os.path.exists(
        os.path.join(scans, gone)) and os.path.exists(outside) and os.path.isdir(OUT),
          f"a delete removes the scan's folder, and not what links in it point to ({st})", body)
    st, _, _ = request(port, "POST", dele, js, "{}")
    check(st == 404, f"deleting it again: no such scan ({st})")
    st, _, body = request(port, "POST", "/api/scans", js, '{"profile": "long"}')
    run = json.loads(body)["id"] if st == 200 else ""
    wait_state(port, run, ("running",))
    st_c, _, _ = request(port, "POST", f"/api/scans/{run}/continue", js, "{}")
    st_o, _, _ = request(port, "POST", f"/api/scans/{run}/continue",
                         {**js, "Origin": "http://evil.example"}, "{}")
    check(st_c == 409 and st_o == 403, f"Continue to a scan that asks nothing is refused, and "
          f"from another site ({st_c}, {st_o})")
    st, _, body = request(port, "POST", f"/api/scans/{run}/delete", js, "{}")
    exists = os.path.isdir(os.path.join(scans, run))
    request(port, "POST", f"/api/scans/{run}/stop", js, "{}")
    wait_state(port, run, ("stopped", "failed", "finished"))
    check(st == 409 and exists, f"the running scan is not deleted ({st})", body)
    st, _, body = request(port, "GET", "/api/status")
    s = json.loads(body)
    check(st == 200 and 0 < s.get("disk_free_bytes", 0) <= s.get("disk_total_bytes", 0),
          f"the status says the disk's free space ({s.get('disk_free_bytes')})")


def profile_cases(port, key):
    """Settings from the page: read, refused with the scanner's own message naming the key,
    values that would write more than one line refused, kept over the old file with a backup,
    or as a new profile (never over another)."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    path = os.path.join(OUT, "fast.ini")
    before = open(path).read()
    st, _, body = request(port, "GET", "/api/profiles/fast")
    vals = json.loads(body).get("values", {}) if st == 200 else {}
    check(st == 200 and vals.get("scan.views") == "4" and vals.get("colour.method") == "none",
          f"a profile's main settings are read ({st}, {vals})")
    st, _, _ = request(port, "POST", "/api/profiles/fast", {"Content-Type": "application/json"},
                       '{"values": {"scan.views": "6"}}')
    check(st == 403, f"a change without the session key is refused ({st})")
    st, _, body = request(port, "POST", "/api/profiles/fast", js, '{"values": {"scan.views": "0"}}')
    msg = json.loads(body).get("error", "")
    check(st == 400 and "[scan] views" in msg and open(path).read() == before,
          f"a value out of range is refused with the scanner's words, naming the key ({msg})")
    bad = ['{"values": {"scan.views": "6\\n[sim]\\nobject = torus"}}',
           '{"values": {"scan.views": "6 ; x"}}', '{"values": {"sim.object": "torus"}}',
           '{"values": {"scan.views": 6}}', '{"values": "views=6"}',
           '{"values": {"scan.views": "' + "9" * 80 + '"}}']
    sts = [request(port, "POST", "/api/profiles/fast", js, b)[0] for b in bad]
    check(sts == [400] * len(bad) and open(path).read() == before,
          f"a second line, a comment, a key the page may not change, a number, no object, a long "
          f"value: each refused, the file as it was ({sts})")
    st, _, _ = request(port, "POST", "/api/profiles/../../etc/passwd", js, '{"values": {}}')
    st2, _, _ = request(port, "POST", "/api/profiles/fast", js,
                        '{"values": {"scan.views": "6"}, "save_as": "../evil"}')
    check(st == 404 and st2 == 400, f"no profile outside the list, no name leaving the folder "
          f"({st}, {st2})")
    st, _, body = request(port, "POST", "/api/profiles/fast", js,
                          '{"values": {"scan.views": "6", "output.max_hole_mm": "10"}}')
    baks = [f for f in os.listdir(OUT) if f.startswith("fast.ini.bak-")]
    now = json.loads(request(port, "GET", "/api/profiles/fast")[2])["values"]
    check(st == 200 and now["scan.views"] == "6" and now["output.max_hole_mm"] == "10"
          and len(baks) == 1 and open(os.path.join(OUT, baks[0])).read() == before
          and "[registration]" in open(path).read(),
          f"a change is kept over the file, the old one beside it, the rest of it untouched "
          f"({st}, {baks})", body)
    st, _, _ = request(port, "POST", "/api/profiles/fast", js,
                       '{"values": {"scan.views": "12"}, "save_as": "fast12"}')
    profiles = json.loads(request(port, "GET", "/api/status")[2])["profiles"]
    st2, _, _ = request(port, "POST", "/api/profiles/fast", js,
                        '{"values": {}, "save_as": "long"}')
    check(st == 200 and "fast12" in profiles and st2 == 409 and
          json.loads(request(port, "GET", "/api/profiles/fast12")[2])["values"]["scan.views"]
          == "12", f"saved as a new profile it is listed; never over another ({st}, {st2})")
    st, _, _ = request(port, "POST", "/api/profiles/fast", {**js, "Origin": "http://evil.example"},
                       '{"values": {"scan.views": "7"}}')
    st2, _, _ = request(port, "POST", "/api/profiles/fast", js,
                        '{"values": ' + "[" * 1000 + "]" * 1000 + "}")
    check(st == 403 and st2 == 400, f"a change from another site, or 1000 deep, is refused "
          f"({st}, {st2})")
    open(path, "w").write(before)
    os.rename(path, path + ".aside")
    os.mkfifo(path)
    try:
        t0 = time.time()
        st, _, _ = request(port, "GET", "/api/profiles/fast", timeout=10)
        st2, _, _ = request(port, "POST", "/api/profiles/fast", js,
                            '{"values": {"scan.views": "7"}}', timeout=10)
        check(st == 500 and st2 == 500 and time.time() - t0 < 5,
              f"a pipe put in the profile's place is refused at once, read or changed "
              f"({st}, {st2})")
    finally:
        os.unlink(path)
        os.rename(path + ".aside", path)


def wait_calibration(port, test, timeout=60):
    until = time.time() + timeout
    while time.time() < until:
        c = json.loads(request(port, "GET", "/api/calibration")[2])
        if test(c):
            return c
        time.sleep(0.2)
    return None


def calibration_cases(port, key, scans):
    """The calibration wizard's requests (issue 32): one job on the rig at a time, the answer
    channel taking only what the question names, once, from this page with its key; bounded
    bodies; Use only for a finished calibration; a stop keeps the captures."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    st, _, body = request(port, "GET", "/api/calibration")
    c = json.loads(body)
    check(st == 200 and c["state"] == "idle" and c["in_use"]["file"].endswith("calib.ini"),
          f"before any calibration: idle, and the file in use named ({st})", body)
    st, _, _ = request(port, "POST", "/api/calibration", {"Content-Type": "application/json"},
                       '{"profile": "asked"}')
    st2, _, _ = request(port, "POST", "/api/calibration", {**js, "Origin": "http://evil.example"},
                        '{"profile": "asked"}')
    st3, _, _ = request(port, "GET", "/api/calibration/answer")
    st4, _, _ = request(port, "POST", "/api/calibration/nothing", js, "{}")
    st5, _, _ = request(port, "POST", "/api/calibration", js, '{"profile": "../../etc/passwd"}')
    check((st, st2, st3, st4, st5) == (403, 403, 405, 404, 400),
          f"a calibration without the key or from another site is not started; GET on a POST, "
          f"no such request, no such profile ({st}, {st2}, {st3}, {st4}, {st5})")
    bad = ['{"exposure_us": 5}', '{"exposure_us": 1e12}', '{"exposure_us": "100"}',
           '{"exposure_us": 1000.5}', '{"exposure_us": -1}', '{"profile": "../fast"}', "[]"]
    sts = [request(port, "POST", "/api/snapshot.png", js, b)[0] for b in bad]
    st, h, png = request(port, "POST", "/api/snapshot.png", js,
                         '{"profile": "fast", "exposure_us": 2000}')
    check(sts == [400] * len(bad) and st == 200 and png[:4] == b"\x89PNG",
          f"a picture at an exposure: out of range, not a whole number, no such profile refused; "
          f"a right one taken ({sts}, {st})")
    before = sorted(os.listdir(scans))
    st, _, body = request(port, "POST", "/api/calibration", js, '{"profile": "asked"}')
    cid = json.loads(body).get("id", "") if st == 200 else ""
    c = wait_calibration(port, lambda c: c.get("question") is not None)
    check(st == 200 and c is not None and c["question"]["answers"] == ["continue"]
          and c["events"][0]["event"] == "calib_start" and sorted(os.listdir(scans)) == before
          and os.path.isdir(os.path.join(OUT, "calibrations", cid)),
          f"a calibration starts and asks its first step; its folder is not among the scans ({st})",
          body)
    busy = [request(port, "POST", p, js, b)[0] for p, b in [
        ("/api/calibration", '{"profile": "asked"}'), ("/api/calibration/verify", "{}"),
        ("/api/scans", "{}"), ("/api/snapshot.png", None), ("/api/calibration/use", "{}"),
        (f"/api/scans/{cid}/continue", "{}"), (f"/api/scans/{cid}/stop", "{}")]]
    check(busy == [409] * 7, f"while it runs: no second calibration, check, scan or picture; "
          f"no Use; the scan requests do not reach it ({busy})")
    bad = ['{"answer": 5}', '{"answer": "' + "c" * 100 + '"}', "{}", '{"answer": "back"}',
           '{"answer": "continue\\nback"}', '{"answer": ""}', "[" * 1000 + "]" * 1000, "not json",
           '{"answer": "continue"} junk']
    sts = [request(port, "POST", "/api/calibration/answer", js, b)[0] for b in bad]
    big = request(port, "POST", "/api/calibration/answer", js, " " * 5000)[0]
    plain = request(port, "POST", "/api/calibration/answer", {"X-Scanner-Key": key},
                    '{"answer": "continue"}')[0]
    foreign = request(port, "POST", "/api/calibration/answer",
                      {**js, "Sec-Fetch-Site": "cross-site"}, '{"answer": "continue"}')[0]
    c = json.loads(request(port, "GET", "/api/calibration")[2])
    check(sts == [400] * len(bad) and big == 413 and plain == 415 and foreign == 403
          and c["question"] is not None and c["stage"] == "calib_place",
          f"answers it does not take (a number, 100 bytes, none, 'back' at the first step, two "
          f"lines, empty, 1000 deep, not JSON, junk after), 5000 bytes, not JSON's type, another "
          f"site: refused, the question still waiting ({sts}, {big}, {plain}, {foreign})")
    wait_calibration(port, lambda c: c.get("pictures", 0) > 0)
    st, h, png = request(port, "GET", "/api/calibration/live.png")
    check(st == 200 and png[:8] == b"\x89PNG\r\n\x1a\n" and h.get("cache-control") == "no-store",
          f"the live picture is served ({st}, {len(png)} bytes)")
    st, _, _ = request(port, "POST", "/api/calibration/answer", js, '{"answer": "continue"}')
    st2, _, _ = request(port, "POST", "/api/calibration/answer", js, '{"answer": "continue"}')
    check(st == 200 and st2 == 409, f"the answer is taken once; a second is refused ({st}, {st2})")
    c = wait_calibration(port, lambda c: any(e["event"] == "calib_capture" for e in c["events"]))
    st, _, _ = request(port, "POST", "/api/calibration/stop", js, "{}")
    c2 = wait_calibration(port, lambda c: c["state"] != "running")
    captures = os.path.join(OUT, "calibrations", cid, "captures")
    check(c is not None and st == 200 and c2 is not None and c2["state"] == "stopped"
          and os.path.isfile(os.path.join(captures, "view_000", "view.ini"))
          and not json.loads(request(port, "GET", "/api/status")[2])["calibrating"],
          f"a stop ends it with its captures kept and the rig free ({st}, {c2 and c2['state']})")
    # a pipe or a link where the live picture belongs: answered at once, nothing served through it
    live = os.path.join(captures, "live.png")
    codes = []
    for plant in ("fifo", "link"):
        if os.path.lexists(live):
            os.unlink(live)
        if plant == "fifo":
            os.mkfifo(live)
        else:
            os.symlink("/etc/passwd", live)
        t0 = time.time()
        st, _, body = request(port, "GET", "/api/calibration/live.png", timeout=10)
        codes.append((st, time.time() - t0 < 5, b"root:" not in body))
    os.unlink(live)
    check(codes == [(404, True, True)] * 2,
          f"a pipe or a link to /etc/passwd as the live picture: 404 at once ({codes})")
    st, _, _ = request(port, "POST", "/api/calibration/use", js, "{}")
    st2, _, _ = request(port, "GET", "/api/calibration?profile=" + "x" * 5000)
    st3, _, _ = request(port, "POST", "/api/calibration/answer", js, '{"answer": "continue"}')
    check(st == 409 and st2 in (200, 414, 431) and st3 == 409,
          f"a stopped calibration cannot be used or answered; a long query is harmless ({st}, "
          f"{st2}, {st3})")


def disk_cases():
    """A scan the disk cannot hold is refused before it starts (a 4 MB file system): 507, how
    much is free and about how much it needs."""
    small = os.path.join(OUT, "small-disk")
    os.makedirs(small, exist_ok=True)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", small],
                      capture_output=True).returncode != 0:
        print("[  NOTE    ] a small disk needs a tmpfs mount (root): its case not run here")
        return
    try:
        port = free_port()
        srv = Server(["--config", os.path.join(OUT, "fast.ini"), "--listen",
                      f"127.0.0.1:{port}", "--scans", small])
        try:
            key = json.loads(request(port, "GET", "/api/session")[2])["key"]
            js = {"Content-Type": "application/json", "X-Scanner-Key": key}
            st, _, body = request(port, "POST", "/api/scans", js, "{}")
            msg = json.loads(body).get("error", "") if body else ""
            check(st == 507 and "the disk holds" in msg and "needs about" in msg
                  and os.listdir(small) == [],
                  f"a scan the disk cannot hold is refused before it starts ({st}: {msg})")
        finally:
            check(srv.stop() == 0, "the small disk's server ends cleanly")
    finally:
        subprocess.run(["umount", small], capture_output=True)


def token_cases():
    port = free_port()
    fast = os.path.join(OUT, "fast.ini")
    rc, err = start_refused(["--config", fast, "--listen", f"127.0.0.1:{port},0.0.0.0:{port + 1}"])
    check(rc == 2 and "token-file" in err, "a token-free server refuses a list with a network "
          "address", err)
    rc, err = start_refused(["--config", fast, "--listen", str(port)])
    check(rc == 2 and "token-file" in err, "and a bare port (every interface)", err)
    tok = os.path.join(OUT, "token")
    for bad, what in [("x" * 300, "255"), ("abcdefgh;ijklmnop", "cookie"),
                      ("abcdefgh ijklmnop", "cookie")]:
        with open(tok, "w") as f:
            f.write(bad + "\n")
        rc, err = start_refused(["--config", fast, "--listen", f"0.0.0.0:{port}",
                                 "--token-file", tok])
        check(rc == 2 and what in err, f"a token {bad[:20]!r}... is refused at start", err)
    os.unlink(tok)
    os.mkfifo(tok)
    try:
        rc, err = start_refused(["--config", fast, "--listen", f"0.0.0.0:{port}",
                                 "--token-file", tok])
        check(rc == 2 and "not a regular file" in err, "a pipe as the token file is refused", err)
    except subprocess.TimeoutExpired:
        check(False, "a pipe as the token file is refused (it hung)")
    os.unlink(tok)
    secret = "correct-horse-battery-staple"
    with open(tok, "w") as f:
        f.write(secret + "\n")
    srv = Server(["--config", fast, "--listen", f"0.0.0.0:{port}", "--token-file", tok,
                  "--scans", os.path.join(OUT, "scans-token")])
    try:
        js = {"Content-Type": "application/json"}
        codes = [request(port, "POST", "/api/login", js, json.dumps({"token": f"guess-{i}"}))[0]
                 for i in range(12)]
        check(codes.count(401) <= 5 and codes[-1] == 429,
              f"wrong tokens are limited: at most 5 in 10 s ({codes})")
        check("wrong token from 127.0.0.1" in srv.text(), "and each is logged with its address")
        st, _, _ = request(port, "POST", "/api/login", js, json.dumps({"token": secret}))
        check(st == 429, f"even the right one waits its turn ({st})")
        auth = {"Authorization": f"Bearer {secret}"}
        st, _, _ = request(port, "GET", "/api/status", auth, host="scanner.local:8080")
        check(st == 200, f"with a token any Host name is answered (the token protects) ({st})")
        st, _, _ = request(port, "GET", "/api/status", {**auth, "Origin": "http://evil.example"})
        check(st == 403, f"but never another site's Origin ({st})")
        st, _, _ = request(port, "POST", "/api/login", js, "[" * 800 + "]" * 800)
        st2, _, _ = request(port, "GET", "/api/status", auth)
        check(st in (400, 429) and st2 == 200, f"deep JSON at the login does not crash it ({st})")
    finally:
        check(srv.stop() == 0, "the token server ends cleanly")


def warning_cases(port, key):
    """The scanner's warnings reach the page: a sphere the volume cuts (issue 30) is said."""
    js = {"Content-Type": "application/json", "X-Scanner-Key": key}
    st, _, body = request(port, "POST", "/api/scans", js, '{"profile": "cut"}')
    sid = json.loads(body)["id"] if st == 200 else ""
    state = wait_state(port, sid, ("finished", "failed")) if st == 200 else None
    warnings = state.get("warnings", []) if state else []
    check(state is not None and state["state"] == "finished" and state["warning_count"] == 1 and
          len(warnings) == 1 and "rises above the fused volume" in warnings[0] and
          "top_mm = 40," in warnings[0] and "set top_mm = " in warnings[0],
          "a scan the volume cuts says so on the page, with the value that holds it", state)
    return sid


def saved_warning_cases(port, cut, scans):
    """After a restart, a scan's warnings come from its warnings.txt: kept, bounded, and a pipe
    planted there hangs nothing."""
    s = json.loads(request(port, "GET", f"/api/scans/{cut}")[2])
    check(s.get("warning_count") == 1 and "rises above the fused volume" in s["warnings"][0],
          "after a restart the cut scan still says what its model lacks", s)
    path = os.path.join(scans, cut, "warnings.txt")
    with open(path, "w") as f:
        f.write(("x" * 5000 + "\n") + "".join(f"line {i}\n" for i in range(1, 200)))
    s = json.loads(request(port, "GET", f"/api/scans/{cut}")[2])
    w = s.get("warnings", [])
    check(len(w) == 8 and len(w[0]) < 400 and w[1] == "line 1" and s["warning_count"] == 64,
          f"a long warnings.txt is read to 8 lines of under 400 bytes, 64 counted "
          f"({len(w)}, {s.get('warning_count')})")
    os.unlink(path)
    os.symlink("/etc/passwd", path)
    st, _, body = request(port, "GET", f"/api/scans/{cut}")
    p = subprocess.run([SCANNER, "report", os.path.join(scans, cut)], capture_output=True,
                       text=True, timeout=60)
    with open(os.path.join(scans, cut, "report.html")) as f:
        report = f.read()
    check(st == 200 and json.loads(body)["warnings"] == [] and b"root:" not in body and
          p.returncode == 0 and "root:" not in report and "<h2>Warnings" not in report,
          f"a link to /etc/passwd as warnings.txt shows nothing of it, nor does the report ({st})")
    os.unlink(path)
    os.mkfifo(path)
    t0 = time.time()
    st, _, body = request(port, "GET", f"/api/scans/{cut}", timeout=15)
    check(time.time() - t0 < 10 and st == 200 and json.loads(body)["warnings"] == [],
          f"a named pipe planted as warnings.txt hangs no answer ({st})")
    try:
        p = subprocess.run([SCANNER, "report", os.path.join(scans, cut)], capture_output=True,
                           text=True, timeout=60)
        check(p.returncode == 0, "nor the report (warnings.txt a pipe)", p.stderr[-600:])
    except subprocess.TimeoutExpired:
        check(False, "scanner report passes over a planted pipe as warnings.txt (it hung)")
    os.unlink(path)


def main():
    shutil.rmtree(OUT, ignore_errors=True)
    os.makedirs(OUT)
    write_configs()
    scans = os.path.join(OUT, "scans")
    port = free_port()
    args = ["--config", os.path.join(OUT, "fast.ini"), "--config", os.path.join(OUT, "long.ini"),
            "--config", os.path.join(OUT, "asked.ini"), "--config", os.path.join(OUT, "cut.ini"),
            "--listen", f"127.0.0.1:{port}",
            "--scans", scans]
    srv = Server(args)
    sid = error = cut = None
    try:
        key = admission(port, scans)
        sid = dos_and_stop(port, key, srv)
        error = resume_cases(port, key, sid, scans)
        path_cases(port, key, scans, sid)
        manage_cases(port, key, scans)
        cut = warning_cases(port, key)
        profile_cases(port, key)
        calibration_cases(port, key, scans)
    finally:
        check(srv.stop() == 0, "the server ends cleanly")
    srv = Server(args)
    try:
        st, _, body = request(port, "GET", f"/api/scans/{sid}")
        s = json.loads(body) if st == 200 else {}
        check(s.get("state") == "failed" and s.get("error") == error and "mesh.stl" in error,
              f"after a restart the failed scan is still failed, with its error ({s})")
        concurrent_thumbs(port, sid)
        saved_warning_cases(port, cut, scans)
        fifo_cases(port, sid, scans)
    finally:
        check(srv.stop() == 0, "the restarted server ends cleanly")
    token_cases()
    disk_cases()
    print(f"[  PASSED  ] {passed} test(s).")
    if failed:
        print(f"[  FAILED  ] {failed} test(s).")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
