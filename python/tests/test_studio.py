"""The studio over HTTP (fretbuzz.studio): it answers loopback clients only (unless started
with --host) and only requests that name it in Host (DNS rebinding) and, for changes, come
from its own page as JSON; it serves the files of its study folder and nothing else
(traversal, absolute paths, symbolic links out, other kinds of file: refused); its queue
never holds more than QUEUE_LIMIT waiting maps, newer what-ifs superseding the oldest; every
value goes through the library's checks and a bad one is answered with the library's
message, keyed by its control, while the studio keeps serving; its maps are the library's
maps (the same verdicts as Bench.map, the changes marked as Bench.compare marks them), filled
in note by note; a note's WAV is a real RIFF/WAVE file; the exported report is one
self-contained HTML file; `fretbuzz studio` serves the page and stops on Ctrl-C."""
import base64
import http.client
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import wave
from html import escape as html_escape

import fretbuzz
from fretbuzz.studio import listen, server
from fretbuzz.studio.app import create_app
from fretbuzz.studio.study import QUEUE_LIMIT, Study, StudyPathError

CLI = os.environ.get("FRETBUZZ_CLI")
# A small, fast instrument: one string, 21 notes, two plucks each, 50 ms at 300 kHz.
QUICK = dict(ensemble=2, fs=3e5, duration=0.05)


def quick_bench(instrument="bass-neck", **kwargs):
    return fretbuzz.Bench(instrument, **{**QUICK, **kwargs})


def wait_for(condition, timeout=60.0, what="the condition"):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def wav_frames(data: bytes):
    """The frames of a WAV file's bytes (RIFF/WAVE checked by the wave module)."""
    import io
    assert data[:4] == b"RIFF" and data[8:12] == b"WAVE", data[:12]
    with wave.open(io.BytesIO(data)) as w:
        return w.getnframes(), w.getframerate(), w.readframes(w.getnframes())


class RunningStudio:
    """The studio served by uvicorn on a free loopback port, in this process."""

    def __init__(self, bench=None, strengths="medium", host=None, start=True, dir=None):
        self.owns_dir = dir is None
        self.dir = dir or tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        self.study = Study(bench or quick_bench(), os.path.join(self.dir, "study"), strengths=strengths, start=start)
        sock = listen("127.0.0.1", 0)
        self.port = sock.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self.server = server(self.study, sock, host)
        self.thread = threading.Thread(target=self.server.run, kwargs={"sockets": [sock]}, daemon=True)
        self.thread.start()
        wait_for(lambda: self.server.started, 20, "the server to start")

    def request(self, method, path, body=None, headers=None):
        """A raw request (the path is sent as it is, never normalised): status, headers, body."""
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        try:
            data = None if body is None else json.dumps(body).encode()
            all_headers = {"Content-Type": "application/json"} if body is not None else {}
            all_headers.update(headers or {})
            connection.request(method, path, body=data, headers=all_headers)
            response = connection.getresponse()
            return response.status, dict(response.getheaders()), response.read()
        finally:
            connection.close()

    def json(self, method, path, body=None):
        status, _, data = self.request(method, path, body)
        return status, json.loads(data)

    def wait_map(self, map_id, timeout=60.0):
        def done():
            record = self.study.maps[map_id]
            return record.status in ("done", "failed", "stopped") and record
        record = wait_for(done, timeout, f"map {map_id}")
        assert record.status == "done", (record.status, record.error)
        return record

    def close(self):
        self.server.should_exit = True
        self.thread.join(timeout=20)
        self.study.close()
        if self.owns_dir:
            shutil.rmtree(self.dir, ignore_errors=True)


def client_at(app, address):
    """The application as a client at `address` would reach it (TestClient's own is 'testclient')."""
    async def shim(scope, receive, send):
        if scope["type"] == "http":
            scope = dict(scope, client=(address, 50000))
        await app(scope, receive, send)
    return shim


class GuardTest(unittest.TestCase):
    """Who may talk to the studio (FastAPI's TestClient through httpx)."""

    PORT = 8035

    @classmethod
    def setUpClass(cls):
        from fastapi.testclient import TestClient
        cls.dir = tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        cls.study = Study(quick_bench(), os.path.join(cls.dir, "study"), start=False)
        cls.TestClient = TestClient

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def client(self, address="127.0.0.1", host=None):
        app = create_app(self.study, port=self.PORT, host=host)
        return self.TestClient(client_at(app, address), base_url=f"http://127.0.0.1:{self.PORT}")

    def test_a_loopback_client_is_served(self):
        for address in ("127.0.0.1", "127.0.0.2", "::1"):
            response = self.client(address).get("/api/state")
            self.assertEqual(response.status_code, 200, address)
            self.assertEqual(response.json()["map"], None)  # the first map waits: no worker here
        page = self.client().get("/")
        self.assertEqual(page.status_code, 200)
        self.assertIn("fretbuzz studio: bass-neck", page.text)

    def test_a_client_not_on_loopback_is_refused_everywhere(self):
        for address in ("192.0.2.7", "10.0.0.1", "2001:db8::1", "testclient"):
            client = self.client(address)
            for path in ("/", "/api/state", "/static/studio.js", "/fragment/maps", "/study/maps/001/x.wav"):
                response = client.get(path)
                self.assertEqual(response.status_code, 403, (address, path))
                self.assertIn("loopback", response.json()["error"])
            response = client.post("/api/what-if", json={"relief": "0.3", "strengths": "medium"})
            self.assertEqual(response.status_code, 403)
        self.assertEqual(len(self.study.pending), 1)  # only the first map: nothing was queued

    def test_with_an_explicit_host_other_computers_are_served(self):
        app = create_app(self.study, port=self.PORT, host="0.0.0.0")
        client = self.TestClient(client_at(app, "192.0.2.7"), base_url=f"http://127.0.0.1:{self.PORT}")
        self.assertEqual(client.get(f"/api/state?token={app.state.token}").status_code, 200)
        # A named address: requests must name it (or a loopback name) in Host.
        app = create_app(self.study, port=self.PORT, host="192.0.2.1")
        client = self.TestClient(client_at(app, "192.0.2.7"), base_url=f"http://192.0.2.1:{self.PORT}")
        self.assertEqual(client.get(f"/api/state?token={app.state.token}").status_code, 200)
        self.assertEqual(client.get("/api/state", headers={"Host": f"evil.example:{self.PORT}"}).status_code, 400)

    def test_a_host_header_that_is_not_the_studio_is_refused(self):
        # DNS rebinding: a page at evil.example, its name resolved to 127.0.0.1, reaches the
        # port from the user's browser; its requests carry its own name in Host.
        client = self.client()
        for host in (f"evil.example:{self.PORT}", "evil.example", f"127.0.0.1.evil.example:{self.PORT}",
                     f"localhost:{self.PORT + 1}", "127.0.0.1", f"127.0.0.1:{self.PORT}x", ""):
            response = client.get("/api/state", headers={"Host": host})
            self.assertEqual(response.status_code, 400, host)
            self.assertIn("Host", response.json()["error"])
        for host in (f"localhost:{self.PORT}", f"127.0.0.1:{self.PORT}", f"[::1]:{self.PORT}", f"LOCALHOST:{self.PORT}"):
            self.assertEqual(client.get("/api/state", headers={"Host": host}).status_code, 200, host)

    def test_changes_come_from_the_page_itself_as_json(self):
        client = self.client()
        pending = len(self.study.pending)
        refused = client.post("/api/what-if", json={"relief": "0.3", "strengths": "medium"},
                              headers={"Origin": "http://evil.example"})
        self.assertEqual(refused.status_code, 403)
        form = client.post("/api/what-if", content=b'{"relief": "0.3", "strengths": "medium"}',
                           headers={"Content-Type": "text/plain"})  # a cross-site form can send this one
        self.assertEqual(form.status_code, 415)
        big = client.post("/api/what-if", content=b" " * 20000, headers={"Content-Type": "application/json"})
        self.assertEqual(big.status_code, 413)
        self.assertEqual(len(self.study.pending), pending)
        ours = client.post("/api/what-if", json={"relief": "0.3", "strengths": "medium"},
                           headers={"Origin": f"http://127.0.0.1:{self.PORT}"})
        self.assertEqual(ours.status_code, 202, ours.text)


class ValidationTest(unittest.TestCase):
    """Every value goes through the library's checks; the answer names the control."""

    @classmethod
    def setUpClass(cls):
        cls.studio = RunningStudio(start=False)
        cls.bench = quick_bench()

    @classmethod
    def tearDownClass(cls):
        cls.studio.close()

    def library_message(self, **change):
        with self.assertRaises(fretbuzz.InputError) as e:
            self.bench.with_changes(**change).instrument.geometry()
        return str(e.exception)

    def refused(self, form):
        pending = [j.id for j in self.studio.study.pending]
        status, body = self.studio.json("POST", "/api/what-if", form)
        self.assertEqual(status, 422, body)
        self.assertEqual([j.id for j in self.studio.study.pending], pending)  # nothing queued
        return body["errors"]

    def test_out_of_range_values_get_the_librarys_message_next_to_their_control(self):
        errors = self.refused({"relief": "50", "action12": {"G": "-1"}, "nut": {"G": "20 mm"}, "fret": "3",
                               "fret_offset": "5", "strengths": "medium"})
        self.assertEqual(set(errors), {"relief", "action12.G", "nut.G", "fret_offset"})
        self.assertEqual(errors["relief"], self.library_message(relief="50"))
        self.assertIn("relief", errors["relief"])
        self.assertIn("[-2, 2] mm", errors["relief"])
        self.assertEqual(errors["action12.G"], self.library_message(action12={"G": "-1"}))
        self.assertEqual(errors["nut.G"], self.library_message(nut={"G": "20 mm"}))
        self.assertEqual(errors["fret_offset"], self.library_message(fret_offsets={3: "5"}))
        self.assertIn("[-1, 1] mm", errors["fret_offset"])

    def test_a_fret_a_string_or_an_attack_that_does_not_exist(self):
        errors = self.refused({"fret": "21", "fret_offset": "0.1", "action12": {"X": "2"}, "strengths": "medium"})
        self.assertEqual(errors["fret"], self.library_message(fret_offsets={21: 0.0}))
        self.assertIn("frets 1 to 20", errors["fret"])
        self.assertEqual(errors["action12.X"], self.library_message(action12={"X": "2"}))
        errors = self.refused({"fret": "two", "fret_offset": "0.1", "strengths": "bogus"})
        self.assertIn("not a fret", errors["fret"])
        with self.assertRaises(fretbuzz.InputError) as e:
            self.bench.check(strengths="bogus")
        self.assertEqual(errors["strengths"], str(e.exception))
        self.assertIn("out of range", self.refused({"strengths": "medium,50 mm"})["strengths"])
        self.assertIn("at least one attack", self.refused({"strengths": ""})["strengths"])
        self.assertIn("choose the fret", self.refused({"fret_offset": "0.1", "strengths": "medium"})["fret"])

    def test_values_of_the_wrong_kind_or_size(self):
        errors = self.refused({"relief": [1], "action12": "2", "saddle": {"G": {"a": 1}}, "strengths": True})
        self.assertEqual(set(errors), {"relief", "action12", "saddle.G", "strengths"})
        self.assertIn("expected a number", errors["relief"])
        self.assertIn("at most", self.refused({"relief": "1" * 200, "strengths": "medium"})["relief"])
        self.assertIn("not a number with its unit", self.refused({"relief": "abc", "strengths": "medium"})["relief"])
        status, _, _ = self.studio.request("POST", "/api/what-if", headers={"Content-Type": "application/json"})
        self.assertEqual(status, 422)
        status, body = self.studio.json("POST", "/api/what-if", "not an object")
        self.assertEqual(status, 422)
        self.assertIn("form", body["errors"])

    def test_the_saddle_box_moves_the_saddle_from_where_it_is(self):
        page = self.studio.request("GET", "/")[2].decode()
        self.assertIn('id="saddle_change.G"', page)
        self.assertNotIn('id="saddle.G"', page)  # no absolute height a luthier cannot measure
        job, _ = self.studio.study.submit_map({"saddle_change": {"G": "-0.25 mm"}, "strengths": "medium"})
        now = job.record.bench.strings_table().iloc[0]["saddle_height_m"]
        was = self.bench.strings_table().iloc[0]["saddle_height_m"]
        self.assertAlmostEqual(1e3 * (now - was), -0.25, places=9)
        self.assertIn("G saddle moved by -0.25 mm", job.record.label)
        errors = self.refused({"saddle_change": {"G": "9 mm"}, "strengths": "medium"})
        with self.assertRaises(fretbuzz.InputError) as e:
            self.bench.with_changes(saddle_change={"G": "9 mm"}).instrument.geometry()
        self.assertEqual(errors["saddle_change.G"], str(e.exception))

    def test_changes_that_are_each_valid_but_not_together_are_refused_as_a_whole(self):
        # A back-bowed neck and a low saddle: each is in range, together the string lies on a fret.
        errors = self.refused({"relief": "-0.5", "saddle": {"G": "1"}, "strengths": "medium"})
        self.assertEqual(list(errors), ["form"])
        self.assertIn("would lie on fret", errors["form"])

    def test_the_studio_keeps_serving_after_bad_values(self):
        self.refused({"relief": "50", "strengths": "medium"})
        status, state = self.studio.json("GET", "/api/state")
        self.assertEqual(status, 200)
        status, body = self.studio.json("POST", "/api/what-if", {"relief": "0.3 mm", "strengths": "medium"})
        self.assertEqual(status, 202, body)
        self.assertEqual(body["label"], "relief 0.3 mm; attack medium")


class QueueTest(unittest.TestCase):
    """At most QUEUE_LIMIT maps wait; a newer what-if supersedes the oldest waiting one."""

    def test_the_queue_is_bounded_and_newer_what_ifs_supersede_older_waiting_ones(self):
        studio = RunningStudio(start=False)  # no worker yet: every job waits
        try:
            answers = []
            for relief in ("0.1", "0.2", "0.3", "0.4", "0.5"):
                status, body = studio.json("POST", "/api/what-if", {"relief": relief, "strengths": "medium"})
                self.assertEqual(status, 202, body)
                answers.append(body)
                self.assertLessEqual(len(studio.study.pending), QUEUE_LIMIT)
            self.assertEqual(QUEUE_LIMIT, 2)
            # The first map (the instrument as loaded) and the what-ifs 0.1 .. 0.3 were superseded, in order.
            superseded = [j["id"] for a in answers for j in a["superseded"]]
            self.assertEqual(superseded, [1, answers[0]["id"], answers[1]["id"], answers[2]["id"]])
            status, state = studio.json("GET", "/api/state")
            self.assertEqual([j["id"] for j in state["jobs"]["pending"]], [answers[3]["id"], answers[4]["id"]])
            self.assertEqual({j["id"]: j["superseded_by"] for j in state["jobs"]["superseded"]},
                             {1: answers[1]["id"], answers[0]["id"]: answers[2]["id"], answers[1]["id"]: answers[3]["id"],
                              answers[2]["id"]: answers[4]["id"]})
            page = studio.request("GET", "/")[2].decode()
            self.assertIn(f"at most {QUEUE_LIMIT} wait behind it", page)
            # A page loaded now starts from the newest what-if's controls.
            self.assertRegex(page, r'<input id="relief"[^>]* value="0.5"')
            studio.study.start()
            last = studio.wait_map(answers[4]["id"])
            self.assertEqual(studio.study.maps[answers[3]["id"]].status, "done")
            for a in answers[:3]:
                self.assertNotIn(a["id"], studio.study.maps)  # never played, nothing kept
                self.assertFalse(os.path.exists(os.path.join(studio.study.folder, f"maps/{a['id']:03d}")))
            self.assertEqual(last.before.id, answers[3]["id"])
        finally:
            studio.close()


class OneStringWhatIfTest(unittest.TestCase):
    """A what-if on one string's action plays that string again and keeps the others' notes
    (and sounds) from the map before: they are what a full map would find, for less time."""

    @classmethod
    def setUpClass(cls):
        cls.bench = fretbuzz.Bench("jazz-bass", ensemble=1, fs=3e5, duration=0.05)
        cls.studio = RunningStudio(bench=cls.bench)
        cls.first = cls.studio.wait_map(1, timeout=300)
        status, body = cls.studio.json("POST", "/api/what-if", {"action12": {"E": "2.2"}, "strengths": "medium"})
        assert status == 202, body
        cls.second = cls.studio.wait_map(body["id"], timeout=300)

    @classmethod
    def tearDownClass(cls):
        cls.studio.close()

    def test_only_the_changed_string_is_played_again(self):
        self.assertIsNone(self.first.replayed)
        self.assertEqual(self.second.replayed, ["E"])
        key = StudioMapTest.key
        full = {key(r): r for r in self.bench.with_changes(action12={"E": "2.2"}).map(strengths="medium")
                .to_dict("records")}
        got = {key(n): n for n in self.second.notes}
        self.assertEqual(set(got), set(full))  # every note, once
        for k, row in full.items():  # the kept ones too: the same verdicts a full map finds
            self.assertEqual((got[k]["verdict"], got[k]["buzz_fraction"]), (row["verdict"], row["buzz_fraction"]), k)
        kept = [n for n in self.second.notes if n["string"] != "E"]
        self.assertTrue(all(n["change"] == "same" for n in kept), [n["change"] for n in kept])
        folder = os.path.join(self.studio.study.folder, self.second.folder)
        for n in self.second.notes:
            if n["audio"]:
                self.assertTrue(os.path.isfile(os.path.join(folder, n["audio"])), n["audio"])
        html = self.studio.request("GET", f"/fragment/maps?map={self.second.id}")[2].decode()
        self.assertIn("Played again: string E", html)

    def test_a_link_planted_in_the_map_before_is_not_followed(self):
        folder = os.path.join(self.studio.study.folder, self.second.folder)
        victim = next(n for n in self.second.notes if n["string"] == "A" and n["audio"])
        secret = os.path.join(self.studio.dir, "secret.wav")
        with open(secret, "wb") as f:
            f.write(b"SECRET")
        os.replace(os.path.join(folder, victim["audio"]), os.path.join(folder, "moved.wav"))
        os.symlink(secret, os.path.join(folder, victim["audio"]))
        status, body = self.studio.json("POST", "/api/what-if", {"action12": {"E": "2.3"}, "strengths": "medium"})
        self.assertEqual(status, 202, body)
        third = self.studio.wait_map(body["id"], timeout=300)
        self.assertEqual(third.replayed, ["E"])
        kept = next(n for n in third.notes if StudioMapTest.key(n) == StudioMapTest.key(victim))
        self.assertEqual(kept["audio"], "")  # kept as a note, without the planted sound
        self.assertFalse(os.path.lexists(os.path.join(self.studio.study.folder, third.folder, victim["audio"])))

    def test_a_change_to_the_whole_neck_plays_every_string(self):
        record = type(self.second)(99, self.bench, "relief", "medium", "maps/099", 84, {"relief": "0.3"})
        record.before = self.first
        self.assertIsNone(Study.replayed_strings(record))
        record.changes, record.strengths = {}, "soft"  # other attacks: nothing to keep either
        self.assertIsNone(Study.replayed_strings(record))


class StudioMapTest(unittest.TestCase):
    """The studio's maps are the library's: its verdicts, its comparison, its WAVs."""

    @classmethod
    def setUpClass(cls):
        cls.studio = RunningStudio()
        cls.first = cls.studio.wait_map(1)
        status, body = cls.studio.json("POST", "/api/what-if", {"relief": "0.2", "strengths": "medium"})
        assert status == 202, body
        cls.second = cls.studio.wait_map(body["id"])

    @classmethod
    def tearDownClass(cls):
        cls.studio.close()

    @staticmethod
    def key(n):
        return (n["string"], n["fret"], n["strength"])

    def test_the_map_is_the_librarys_map(self):
        bench = quick_bench()
        for record, expected in ((self.first, bench.map(strengths="medium")),
                                 (self.second, bench.with_changes(relief="0.2").map(strengths="medium"))):
            got = {self.key(n): n for n in record.notes}
            self.assertEqual(len(got), len(expected))
            for row in expected.to_dict("records"):
                n = got[self.key(row)]
                self.assertEqual(n["buzz_fraction"], row["buzz_fraction"], self.key(row))
                self.assertEqual(n["touch_fraction"], row["touch_fraction"], self.key(row))

    def test_the_changes_are_the_librarys_comparison_and_are_marked_on_the_map(self):
        compared = fretbuzz.Bench.compare([{k: v for k, v in n.items() if k not in ("change", "reason", "before")}
                                           for n in self.second.notes], self.first.notes)
        expected = {self.key(r): r["change"] for r in compared.to_dict("records")}
        self.assertEqual({self.key(n): n["change"] for n in self.second.notes}, expected)
        changed = [k for k, c in expected.items() if c in ("worse", "better", "moved")]
        self.assertTrue(changed, "a relief from 0.54 to 0.2 mm changes the map of bass-neck")
        html = self.studio.request("GET", f"/fragment/maps?map={self.second.id}")[2].decode()
        self.assertEqual(len(re.findall(r'data-change="(worse|better|moved)"', html)), len(changed))
        self.assertIn(f"Before: map {self.first.id}", html)
        for string, fret, strength in changed:
            cell = re.search(rf'id="note-{string}-{fret}-{strength}"[^>]*aria-label="([^"]*)"', html).group(1)
            self.assertRegex(cell, r"(worse|better) than before|another fret than before")
            # Said as the page says it (setup_report.change_text): what it was, then what it is.
            self.assertRegex(cell, r": .+ \u2192 .+\)$")

    def test_every_cell_says_its_verdict_and_attack_in_words(self):
        html = self.studio.request("GET", f"/fragment/maps?map={self.first.id}")[2].decode()
        labels = re.findall(r'id="note-[^"]*"[^>]*aria-label="([^"]*)"', html)
        self.assertEqual(len(labels), 21)
        for label in labels:
            self.assertRegex(label, r"^G string, (open|fret \d+), medium attack: "
                                    r"(clean|marginal|buzzes), \d+/\d+ plucks buzz")

    def test_a_notes_wav_is_served_from_the_study_folder(self):
        note = next(n for n in self.first.notes if n["touch_fraction"] > 0)
        html = self.studio.request("GET", f"/fragment/note?map=1&string=G&fret={note['fret']}&strength=medium")[2].decode()
        src = re.search(r'<audio id="note-audio"[^>]* src="([^"]+)"', html).group(1)
        # The pluck its verdict rests on: the map's WAV when that is the attack itself, else its own beside it.
        member = note["deciding_pluck"]
        name = note["audio"] if member == 0 else f"{note['audio'][:-len('.wav')]}-pluck{member + 1}.wav"
        self.assertEqual(src, f"/study/maps/001/{name}")
        status, headers, data = self.studio.request("GET", src)
        self.assertEqual(status, 200)
        self.assertEqual(headers["content-type"], "audio/wav")
        frames, rate, samples = wav_frames(data)
        self.assertEqual(rate, 48000)
        self.assertGreater(frames, 0.9 * QUICK["duration"] * rate)
        self.assertTrue(any(samples))
        # Its contacts: those of the library's record of the same pluck.
        played = quick_bench().note("G", note["fret"], "medium", member=member)
        self.assertEqual(html.count("<circle"), len(played["contacts"]))

    def test_the_map_fills_in_note_by_note(self):
        status, body = self.studio.json("POST", "/api/what-if", {"relief": "0.3", "strengths": "soft,medium"})
        self.assertEqual(status, 202)
        seen = set()
        while True:
            state = self.studio.json("GET", "/api/state")[1]
            if state["map"]["id"] == body["id"]:
                seen.add(state["map"]["done"])
                if state["map"]["status"] == "done":
                    break
            time.sleep(0.005)
        self.assertEqual(max(seen), 42)
        self.assertTrue(any(0 < d < 42 for d in seen), sorted(seen))

    def test_the_advice_is_the_librarys_and_takes_no_maps_number(self):
        status, body = self.studio.json("POST", "/api/advice", {})
        self.assertEqual((status, body["id"]), (202, f"advice {self.second.id}"))
        wait_for(lambda: self.second.advice_status in ("done", "failed"), 60, "the advice")
        self.assertEqual(self.second.advice_status, "done", self.second.advice_error)
        expected = quick_bench().with_changes(relief="0.2").advise(
            [{k: v for k, v in n.items() if k not in ("change", "reason", "before")} for n in self.second.notes], strength="medium")
        for key in ("lowest_action", "proud_frets", "relief"):
            self.assertEqual(self.second.advice[key], expected[key])
        html = self.studio.request("GET", f"/fragment/advice?map={self.second.id}")[2].decode()
        self.assertIn(f"String G: action at fret 12 now {expected['lowest_action'][0]['action12_mm']:.2f} mm", html)
        status, body = self.studio.json("POST", "/api/what-if", {"relief": "0.25", "strengths": "medium"})
        self.assertEqual(body["id"], max(self.studio.study.maps))
        self.studio.wait_map(body["id"])

    def test_the_fret_dress_is_the_librarys(self):
        # The dress works on the newest finished map (another test may have added one after the
        # second): the library's dress of that map's bench and notes.
        record = self.studio.study.done
        status, body = self.studio.json("POST", "/api/dress", {})
        self.assertEqual((status, body["id"]), (202, f"dress {record.id}"))
        wait_for(lambda: record.dress_status in ("done", "failed"), 120, "the fret dress")
        self.assertEqual(record.dress_status, "done", record.dress_error)
        expected = record.bench.dress(
            [{k: v for k, v in n.items() if k not in ("change", "reason", "before")} for n in record.notes], strength="medium")
        for key in ("frets", "fall_away", "clean", "unresolved"):
            self.assertEqual(record.dress[key], expected[key])
        # While it ran, the page could say how far it had got: the notes its probes played.
        if expected["maps_played"]:
            self.assertRegex(record.dress_progress, r"^\d+ notes? played in \d+ probes?; the last, G fret \d+: ")
        record.dress_status = "running"  # the fragment of a running dress shows it
        try:
            html = self.studio.request("GET", f"/fragment/dress?map={record.id}")[2].decode()
            self.assertIn(html_escape(record.dress_progress or "Its first probe is under way."), html)
        finally:
            record.dress_status = "done"
        html = self.studio.request("GET", f"/fragment/dress?map={record.id}")[2].decode()
        self.assertIn('data-status="done"', html)
        self.assertTrue("take off" in html or "Nothing to take off" in html, html)

    def test_the_export_is_one_self_contained_html_file(self):
        status, body = self.studio.json("POST", "/api/export", {"map": self.second.id})
        self.assertEqual(status, 200, body)
        path = body["file"]
        self.assertTrue(path.startswith(self.studio.study.folder + os.sep))
        with open(path, encoding="utf-8") as f:
            html = f.read()
        self.assertEqual(self.studio.request("GET", body["url"])[2].decode(), html)
        # Every note's sound, of both maps, as Ogg Vorbis (a tenth of a WAV): the report stays small.
        sounds = re.findall(r'data-sound="data:audio/ogg;base64,([A-Za-z0-9+/=]+)"', html)
        self.assertEqual(len(sounds), len([n for n in self.second.notes + self.first.notes if n["audio"]]))
        self.assertEqual(base64.b64decode(sounds[0])[:4], b"OggS")
        self.assertNotIn("audio/wav", html)
        self.assertLess(len(html.encode()), 2_000_000)
        # Dated, and in three parts: the instrument as found, what is recommended, and after.
        self.assertRegex(html, r"Dated \d{4}-\d\d-\d\d \d\d:\d\d")
        for part in ('<section id="found">', '<section id="recommended">', '<section id="after">', "<svg",
                     "vertical scale exaggerated", f"As found: {self.first.label}", f"After: {self.second.label}",
                     "fret 12: "):
            self.assertTrue(part in html, part)  # the neck with its gaps, the map as found and after
        # Nothing to fetch: no links, no scripts, no style sheets, no study files.
        self.assertIsNone(re.search(r'(src|href)="(?!data:)', html))
        self.assertFalse("/study/" in html)


class PlayersReportTest(unittest.TestCase):
    """The player's report clicked on the map, calibrated by the library (Bench.calibrate), the
    map and advice played at the player's touch (Bench.with_player, as --player), the advice's
    tolerate choices as --tolerate takes them, and a cell's pluck the one its verdict rests on."""

    @classmethod
    def setUpClass(cls):
        cls.studio = RunningStudio()
        cls.first = cls.studio.wait_map(1)

    @classmethod
    def tearDownClass(cls):
        cls.studio.close()

    def refused(self, path, body, field):
        status, answer = self.studio.json("POST", path, body)
        self.assertEqual(status, 422, answer)
        self.assertIn(field, answer["errors"])
        return answer["errors"][field]

    def test_bad_notes_of_the_report_are_refused_naming_what_is_wrong(self):
        note = {"string": "G", "fret": 3, "strength": "medium", "heard": "buzz"}
        self.assertIn("heard:", self.refused("/api/heard", {**note, "heard": "loud"}, "heard"))
        self.assertIn("string:", self.refused("/api/heard", {**note, "string": "Q"}, "heard"))
        message = self.refused("/api/heard", {**note, "fret": 99}, "heard")
        self.assertIn(f"0 to {quick_bench().frets}", message)
        self.assertIn("strength", self.refused("/api/heard", {**note, "strength": "thunder"}, "heard"))
        self.assertEqual(self.studio.study.heard, {})
        # Playing at the player's touch before any calibration: refused, naming the control.
        self.assertIn("player:", self.refused("/api/what-if", {"strengths": "medium", "player": True}, "player"))

    def test_the_advice_takes_the_tolerate_choices_of_the_command_line(self):
        with self.assertRaises(fretbuzz.InputError) as e:
            quick_bench().advise(self.first.notes, strength="medium", tolerate="above=99")
        self.assertEqual(self.refused("/api/advice", {"tolerate": "above=99"}, "tolerate"), str(e.exception))
        self.assertIn("tolerate", str(e.exception))
        status, body = self.studio.json("POST", "/api/advice", {"tolerate": "marginal,above=15"})
        self.assertEqual(status, 202, body)
        record = self.studio.study.maps[body["map"]]
        wait_for(lambda: record.advice_status in ("done", "failed"), 120, "the advice")
        self.assertEqual(record.advice_status, "done", record.advice_error)
        expected = record.bench.advise([{k: v for k, v in n.items() if k not in ("change", "reason", "before")}
                                        for n in record.notes], strength="medium", tolerate="marginal,above=15")
        self.assertEqual(record.advice["tolerated"], expected["tolerated"])
        self.assertEqual(record.advice["lowest_action"], expected["lowest_action"])
        html = self.studio.request("GET", f"/fragment/advice?map={record.id}")[2].decode()
        self.assertIn(f"tolerating {expected['tolerated']}", html)
        # The page states set-up practice's defaults, as the library words them.
        page = self.studio.request("GET", "/")[2].decode()
        self.assertIn(f"tolerating {fretbuzz._core._setup_tolerance(quick_bench().instrument, '')}", page)

    def test_a_cell_plays_the_pluck_its_verdict_rests_on(self):
        audible = quick_bench().settings["audible_dB"]

        def loud(level):
            return level is not None and level >= audible
        def heard(n):  # what the pluck a verdict rests on must sound like: a marginal note's loudest
            return n["verdict"] == "buzzes" or (n["verdict"] == "marginal" and any(map(loud, n["pluck_dB"])))
        # The notes whose first pluck (the attack itself) says otherwise than the verdict first.
        notes = sorted((n for n in self.first.notes if n["verdict"] and n["status"] == "ok"),
                       key=lambda n: loud(n["pluck_dB"][0]) == heard(n))
        self.assertTrue(notes)
        for n in notes[:4]:
            status, _, html = self.studio.request(
                "GET", f"/fragment/note?map=1&string={n['string']}&fret={n['fret']}&strength=medium")
            self.assertEqual(status, 200)
            html = html.decode()
            member = int(re.search(r'data-member="(\d+)"', html).group(1))
            self.assertEqual(member, n["deciding_pluck"])
            verdict = "buzz" if heard(n) else "clean"
            self.assertEqual(re.search(r'data-pluck-heard="(\w+)"', html).group(1), verdict, (n["fret"], n["pluck_dB"]))
            pluck = quick_bench().note(n["string"], n["fret"], "medium", member=member)
            self.assertEqual(pluck["touched"] and loud(pluck["buzz_dB"]), verdict == "buzz", (n["fret"], member))
            if member:  # its own sound, beside the map's
                self.assertIn(f"-pluck{member + 1}.wav", html)

    def test_the_report_is_calibrated_by_the_library_and_then_played_at_the_players_touch(self):
        verdicts = {(n["string"], n["fret"]): n["verdict"] for n in self.first.notes}
        marked = [(k, "buzz" if v == "buzzes" else "clean") for k, v in verdicts.items() if v][:6]
        self.assertTrue(marked)
        for (string, fret), heard in marked:
            status, body = self.studio.json("POST", "/api/heard", {"string": string, "fret": fret, "strength": "medium",
                                                                     "heard": heard})
            self.assertEqual(status, 200, body)
        self.assertEqual(body["heard"], len(marked))
        report = self.studio.study.report_csv()
        self.assertEqual(report.splitlines()[0], "string,fret,strength,heard")
        self.assertEqual(len(report.splitlines()), len(marked) + 1)
        status, body = self.studio.json("POST", "/api/calibrate", {})
        self.assertEqual(status, 202, body)
        study = self.studio.study
        wait_for(lambda: study.calibration_status in ("done", "failed"), 120, "the calibration")
        self.assertEqual(study.calibration_status, "done", study.calibration_error)
        expected = quick_bench().calibrate(report)
        for key in ("attack_scale", "attack_scale_low", "attack_scale_high", "statement", "disagreeing", "explained"):
            self.assertEqual(study.calibration[key], expected[key], key)
        html = self.studio.request("GET", "/fragment/player")[2].decode()
        self.assertIn(f"Attack scale {expected['attack_scale']:.2f}", html)
        self.assertIn(expected["statement"].split(".")[0], html)
        # The calibrated map: the newest finished map's set-up at the player's touch, and its advice.
        wait_for(lambda: study.calibrated_map is not None, 60, "the calibrated map")
        record = self.studio.wait_map(study.calibrated_map, 120)
        self.assertEqual(record.attack_scale, expected["attack_scale"])
        self.assertIn("the player's touch", record.label)
        touch = quick_bench().with_player(expected)
        library = {(r["string"], r["fret"]): r["buzz_fraction"] for r in touch.map(strengths="medium").to_dict("records")}
        self.assertEqual({(n["string"], n["fret"]): n["buzz_fraction"] for n in record.notes}, library)
        wait_for(lambda: record.advice_status in ("done", "failed"), 120, "the calibrated advice")
        self.assertEqual(record.advice_status, "done", record.advice_error)
        advice = touch.advise([{k: v for k, v in n.items() if k not in ("change", "reason", "before")}
                               for n in record.notes], strength="medium")
        self.assertEqual(record.advice["lowest_action"], advice["lowest_action"])
        # A later what-if at the player's touch.
        status, body = self.studio.json("POST", "/api/what-if", {"relief": "0.2", "strengths": "medium", "player": True})
        self.assertEqual(status, 202, body)
        later = self.studio.wait_map(body["id"], 120)
        self.assertEqual(later.bench.attack_scale, expected["attack_scale"])


class StudyFilesTest(unittest.TestCase):
    """The studio serves the files of its study folder and nothing else."""

    @classmethod
    def setUpClass(cls):
        cls.studio = RunningStudio()
        cls.studio.wait_map(1)
        folder = cls.studio.study.folder
        cls.outside = os.path.join(cls.studio.dir, "secret.html")
        with open(cls.outside, "w") as f:
            f.write("TOP-SECRET-CONTENT")
        os.symlink(cls.outside, os.path.join(folder, "link.html"))
        os.symlink(cls.studio.dir, os.path.join(folder, "up"))
        os.symlink(os.path.join(folder, "maps"), os.path.join(folder, "inside"))
        with open(os.path.join(folder, "notes.toml"), "w") as f:
            f.write("x = 1")

    @classmethod
    def tearDownClass(cls):
        cls.studio.close()

    def assertRefused(self, path):
        status, _, data = self.studio.request("GET", path)
        self.assertIn(status, (403, 404), path)
        self.assertNotIn(b"TOP-SECRET-CONTENT", data)
        self.assertNotIn(b"root:", data)
        return status

    def test_a_wav_of_the_study_is_served(self):
        name = self.studio.study.maps[1].notes[0]["audio"]
        status, _, data = self.studio.request("GET", f"/study/maps/001/{name}")
        self.assertEqual(status, 200)
        self.assertEqual(data[:4], b"RIFF")
        # Through a link that stays inside the folder, too.
        self.assertEqual(self.studio.request("GET", f"/study/inside/001/{name}")[0], 200)

    def test_traversal_absolute_paths_and_links_out_are_refused(self):
        for path in ("/study/../../../../etc/passwd", "/study/..%2f..%2f..%2f..%2fetc%2fpasswd",
                     "/study/maps/../../secret.html", "/study/maps/%2e%2e/%2e%2e/secret.html",
                     "/study/%2fetc%2fpasswd", "/study//etc/passwd", "/study/link.html", "/study/up/secret.html",
                     "/study/maps/001/..%5c..%5csecret.html", "/study/%00", "/study/./maps/001"):
            self.assertRefused(path)
        self.assertEqual(self.assertRefused("/study/link.html"), 403)
        self.assertEqual(self.assertRefused("/study/up/secret.html"), 403)
        for relative in ("../secret.html", "/etc/passwd", "link.html", "up/secret.html", "maps/../../secret.html"):
            with self.assertRaises(StudyPathError, msg=relative):
                self.studio.study.path(relative)

    def test_only_the_studys_own_kinds_of_file_are_served(self):
        self.assertEqual(self.assertRefused("/study/notes.toml"), 404)
        self.assertEqual(self.assertRefused("/study/maps"), 404)
        self.assertEqual(self.assertRefused("/study/maps/001/none.wav"), 404)


@unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
class StudioCommandTest(unittest.TestCase):
    def test_the_command_serves_the_page_and_stops_on_ctrl_c(self):
        with tempfile.TemporaryDirectory() as d:
            process = subprocess.Popen([CLI, "studio", "bass-neck", "--port", "0", "--study", os.path.join(d, "study"),
                                        "--ensemble", "2", "--fs", "3e5", "--duration", "0.05"],
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
            try:
                line = process.stdout.readline()
                url = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
                self.assertIsNotNone(url, line + process.stderr.read() if process.poll() is not None else line)
                connection = http.client.HTTPConnection("127.0.0.1", int(url.group(1)), timeout=30)
                connection.request("GET", "/")
                response = connection.getresponse()
                self.assertEqual(response.status, 200)
                self.assertIn(b"fretbuzz studio: bass-neck", response.read())
                connection.close()
            finally:
                os.killpg(process.pid, signal.SIGINT)  # Ctrl-C reaches the whole process group
                out, err = process.communicate(timeout=30)
            self.assertEqual(process.returncode, 0, err)

    def test_bad_values_exit_2_naming_them_and_write_nothing(self):
        with tempfile.TemporaryDirectory() as d:
            study = os.path.join(d, "study")
            for args, word in ((["--ensemble", "0"], "ensemble"), (["--strength", "bogus"], "not an attack"),
                               (["--port", "70000"], "--port"), (["nothere"], "unknown instrument")):
                run = subprocess.run([CLI, "studio", *([] if args == ["nothere"] else ["bass-neck"]), *args,
                                      "--study", study], capture_output=True, text=True, timeout=60)
                self.assertEqual(run.returncode, 2, run.stderr)
                self.assertIn(word, run.stderr)
                self.assertFalse(os.path.exists(study))


if __name__ == "__main__":
    unittest.main()
