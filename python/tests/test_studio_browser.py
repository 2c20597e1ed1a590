"""The studio in a real browser (Selenium with Debian's chromium-driver, headless): the page
loads and its map fills in; a note's audio element has a playable WAV source (the file is a
RIFF/WAVE with samples, the browser can play the type and loads it without error) and its
contacts are drawn; a new relief is played and the map changes against the one before (the
changed cells marked); an out-of-range value is answered next to its control with the
library's message while the studio keeps serving; the advice and the report come on request.

Each cell shows how much harder than the attack its note stays clean (the map's
clean_up_to, as the library gives it); the neck's side views write the gaps at the nut,
fret 1, fret 12 and the last fret (mm and inches, the library's geometry); a clicked note
draws its stopped string over the frets and its sound lasts at least 1.5 s; the fret dress
and a dated report in three parts come on request.

The player's report (PlayersReportInTheBrowserTest): a buzzing cell whose first pluck is not
heard plays the pluck its verdict rests on, which is; notes marked "This buzzes for me" /
"Clean for me" are marked on the map; the calibration shows the library's scale, interval and
statement, then the map and the advice at the player's touch; the tolerate box takes
--tolerate's choices and answers a bad one with the library's message; a later what-if plays
at the player's touch.

With FRETBUZZ_SCREENSHOTS=DIR (relative to the source tree, e.g. docs/figures) the same
steps run on the built-in jazz-bass at its own settings and save the docs' screenshots
there: studio-map.png, studio-what-if.png, studio-note.png, studio-neck.png, studio-advice.png,
studio-dress.png, studio-report.png.
"""
import http.client
import io
import os
import re
import shutil
import sys
import tempfile
import unittest
import urllib.parse

import fretbuzz
from test_studio import RunningStudio, quick_bench, wav_frames

SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCREENSHOTS = os.environ.get("FRETBUZZ_SCREENSHOTS")
CHROMEDRIVER, CHROMIUM = "/usr/bin/chromedriver", "/usr/bin/chromium"
# The what-if: the truss rod tightened (docs/setup.md's example on the Jazz Bass: 0.54 to 0.3 mm).
RELIEF = "0.3" if SCREENSHOTS else "0.2"


def browser(profile):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                     "--disable-component-update", "--no-first-run", "--disable-sync", "--disable-extensions",
                     "--disable-dev-shm-usage", f"--user-data-dir={profile}", "--window-size=1400,1000"):
        options.add_argument(argument)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


class BrowserSession(unittest.TestCase):
    """A studio and a headless Chromium on it, with the helpers the tests share (no test of its own)."""

    @classmethod
    def tearDownClass(cls):
        cls.driver.quit()
        cls.studio.close()
        shutil.rmtree(cls.profile, ignore_errors=True)

    # Helpers ---------------------------------------------------------------------------

    def wait(self, condition, what, timeout=None):
        from selenium.webdriver.support.ui import WebDriverWait
        return WebDriverWait(self.driver, timeout or self.timeout, poll_frequency=0.1).until(
            lambda d: condition(d), message=f"waiting for {what}")

    def css(self, selector):
        from selenium.webdriver.common.by import By
        return self.driver.find_elements(By.CSS_SELECTOR, selector)

    def map_done(self, map_id):
        return self.wait(lambda d: self.css(f'#map-now[data-map-id="{map_id}"][data-status="done"]'), f"map {map_id}")[0]

    def cells(self, within):
        """The map's cells under `within`, read at once (the page redraws the map as notes
        finish): {id: {kind, label, text, change}}."""
        return self.driver.execute_script("""
            const cells = {};
            document.querySelectorAll(arguments[0] + " button.note").forEach((b) => {
              cells[b.id] = {kind: b.dataset.kind, label: b.getAttribute("aria-label"), text: b.innerText,
                             change: b.dataset.change || ""};
            });
            return cells;""", within)

    def fetch(self, url):
        parts = urllib.parse.urlsplit(url)
        connection = http.client.HTTPConnection(parts.hostname, parts.port, timeout=30)
        connection.request("GET", parts.path)
        response = connection.getresponse()
        data = response.read()
        connection.close()
        return response.status, response.getheader("content-type"), data

    def shoot(self, element, name):
        """A screenshot for the docs, as a 256-colour PNG (small) where Pillow is installed."""
        if not self.shots:
            return
        if element is None:  # the window as the user first sees it
            png = self.driver.get_screenshot_as_png()
        else:  # the whole panel: a window tall enough to hold it
            height = self.driver.execute_script("return document.documentElement.scrollHeight")
            self.driver.set_window_size(1400, height + 200)
            self.driver.execute_script("arguments[0].scrollIntoView()", element)
            png = element.screenshot_as_png
            self.driver.set_window_size(1400, 1000)
        path = os.path.join(self.shots, f"studio-{name}.png")
        try:
            from PIL import Image
            Image.open(io.BytesIO(png)).convert("RGB").quantize(colors=256, method=2).save(path, optimize=True)
        except ImportError:
            with open(path, "wb") as f:
                f.write(png)

    def play(self, **values):
        """Types values into the controls (by id) and plays the map."""
        for control, value in values.items():
            field = self.css(f'[id="{control}"]')[0]
            field.clear()
            field.send_keys(value)
        self.css("#play")[0].click()



class StudioInTheBrowserTest(BrowserSession):
    @classmethod
    def setUpClass(cls):
        if SCREENSHOTS:
            cls.bench, cls.timeout = fretbuzz.Bench("jazz-bass"), 300
            cls.shots = os.path.join(SOURCE, SCREENSHOTS)
            os.makedirs(cls.shots, exist_ok=True)
        else:
            cls.bench, cls.timeout, cls.shots = quick_bench(), 60, None
        cls.studio = RunningStudio(cls.bench, strengths="medium")
        cls.profile = tempfile.mkdtemp(prefix="fretbuzz-studio-chromium-")
        cls.driver = browser(cls.profile)

    # The test: one session, the luthier's loop ----------------------------------------

    def test_the_luthiers_loop(self):
        d = self.driver
        d.get(self.studio.url + "/")
        self.assertIn("fretbuzz studio", d.title)
        self.map_done(1)
        cells = self.cells("#map-now")
        self.assertEqual(len(cells), len(self.bench.strings) * (self.bench.frets + 1))
        for cell in cells.values():  # each verdict in words, the attack named, not colour alone
            self.assertRegex(cell["label"], r" attack: ")
            self.assertIn("medium", cell["text"])
        # A cell's number: how much harder than the attack the note stays clean, the library's clean_up_to.
        from fretbuzz.setup_report import clean_up_to_text
        first_map = self.studio.study.maps[1]
        for n in first_map.notes:
            cell = cells[f"note-{n['string']}-{n['fret']}-{n['strength']}"]
            if clean_up_to_text(n):
                self.assertTrue(cell["text"].startswith(clean_up_to_text(n)), (cell["text"], n["clean_up_to"]))
        self.assertTrue(any(re.match(r"[0-9.]+x", c["text"]) for c in cells.values()))
        # Marginal notes hatched: they differ from clean ones with the colour taken away.
        for key, c in cells.items():
            image = d.execute_script("return getComputedStyle(document.getElementById(arguments[0]).parentElement)"
                                     ".backgroundImage", key)
            self.assertEqual(c["kind"] == "marginal", "gradient" in image, (key, c["kind"], image))
        self.wait(lambda d: self.css("#neck figure svg"), "the neck")
        self.assertIn("vertical scale exaggerated", self.css("#neck svg")[0].text)
        self.assertEqual(len(self.css("#neck figure")), len(self.bench.strings))
        # The gaps a luthier measures, written on the neck: the library's, in mm and inches.
        table = self.bench.strings_table()
        gaps = [t.get_attribute("textContent") for t in self.css("#neck figure:first-of-type text.gap")]
        action = 1e3 * table.iloc[0]["action12_m"]
        self.assertEqual([g.split(":")[0] for g in gaps], ["nut", "fret 1", "fret 12", f"fret {self.bench.frets}"])
        self.assertEqual(gaps[2], f"fret 12: {action:.2f} mm / {action / 25.4:.3f} in")
        nut = 1e3 * table.iloc[0]["nut_gap_m"]
        self.assertIn(f"fret 1: {nut:.2f} mm", gaps[1])
        if self.shots:
            print(f"\n{self.css('#map-now .map-title')[0].text}", file=sys.stderr)
        self.shoot(None, "map")

        # What if the truss rod is tightened?
        self.play(relief=RELIEF)
        second = self.map_done(2)
        self.assertIn(f"relief {RELIEF} mm", second.text)
        now = self.cells("#map-now")
        changed = [c for c in now.values() if c["change"]]
        self.assertTrue(changed, "a flatter neck changes the map")
        for cell in changed:
            self.assertRegex(cell["label"], r"than before")
            self.assertRegex(cell["text"], "[\u25b2\u25bc\u2194]")  # the change in text, not only the outline
        counts = re.search(r"Against map 1: (\d+) worse .*, (\d+) better .*, (\d+) against another fret", second.text)
        self.assertEqual(sum(int(c) for c in counts.groups()), len(changed))
        self.assertNotEqual({k: c["text"] for k, c in now.items()}, {k: c["text"] for k, c in cells.items()})
        before = self.cells("details.before")
        self.assertEqual({k.replace("before-", "note-"): c["kind"] for k, c in before.items()},
                         {k: c["kind"] for k, c in cells.items()})
        self.wait(lambda d: f"relief {float(RELIEF):.2f} mm" in self.css("#neck figcaption")[0].text, "the neck redrawn")
        if self.shots:
            print(f"\n{self.css('#map-now .map-title')[0].text}", file=sys.stderr)
        self.shoot(self.css("#map-panel")[0], "what-if")
        self.shoot(self.css("#neck-panel")[0], "neck")

        # A note: its sound and its contacts. The one that stays clean up to the weakest attack.
        def up_to(cell):  # "0.45x" -> 0.45, "3x+" -> 3
            return float(re.search(r"([0-9.]+)x", cell["text"]).group(1))
        buzzing = sorted((k for k, c in now.items() if c["kind"] in ("buzzes", "marginal") and re.search(r"[0-9.]+x", c["text"])),
                         key=lambda k: up_to(now[k]))
        self.assertTrue(buzzing)
        self.css(f'[id="{buzzing[0]}"]')[0].click()
        self.wait(lambda d: self.css("#note-now audio"), "the note")
        audio = self.css("#note-audio")[0]
        src = audio.get_attribute("src")
        self.assertIn("/study/maps/002/note-", src)
        status, kind, data = self.fetch(src)
        self.assertEqual((status, kind), (200, "audio/wav"))
        frames, rate, samples = wav_frames(data)
        self.assertGreater(frames, 0)
        self.assertTrue(any(samples))
        self.assertIn(d.execute_script("return arguments[0].canPlayType('audio/wav')", audio), ("maybe", "probably"))
        self.wait(lambda d: d.execute_script("return arguments[0].readyState >= 1 || arguments[0].error !== null", audio),
                  "the audio's metadata", 30)
        self.assertIsNone(d.execute_script("return arguments[0].error && arguments[0].error.code", audio))
        self.assertAlmostEqual(d.execute_script("return arguments[0].duration", audio), frames / rate, delta=0.01)
        self.assertGreaterEqual(frames / rate, 1.5 - 1e-3)  # a note to judge by ear, not a click
        # Its stopped string, drawn over the frets of its string from the fret it is stopped on.
        stopped = self.css("#note-now svg line.stopped")
        if int(self.css("#note-now")[0].get_attribute("data-fret")) > 0:
            self.assertEqual(len(stopped), 1)
        # Its contacts: the library's record of the pluck its verdict rests on, one dot per stretch of 0.5 ms.
        note = self.css("#note-now")[0]
        played = self.bench.with_changes(relief=RELIEF).note(
            note.get_attribute("data-string"), int(note.get_attribute("data-fret")), "medium",
            member=int(note.get_attribute("data-member")))
        self.assertGreater(len(played["contacts"]), 0)  # the loudest pluck of a note that buzzes touches
        self.assertEqual(len(self.css("#note-now svg.contacts circle")), len(played["contacts"]))
        self.shoot(self.css("#note-panel")[0], "note")

        # An out-of-range relief: the library's message next to the control; the studio serves on.
        self.play(relief="50")
        self.wait(lambda d: self.css("#error-relief")[0].text, "the relief's error")
        message = self.css("#error-relief")[0].text
        self.assertIn("relief", message)
        self.assertIn("out of range", message)
        self.assertIn("[-2, 2] mm", message)
        self.assertEqual(self.css("#relief")[0].get_attribute("aria-invalid"), "true")
        self.assertEqual(self.css("#map-now")[0].get_attribute("data-map-id"), "2")
        self.play(relief="0.25")
        self.map_done(3)
        self.assertEqual(self.css("#error-relief")[0].text, "")

        # Back to the what-if for the advice and the report.
        self.play(relief=RELIEF)
        self.map_done(4)
        self.css("#advise")[0].click()
        self.wait(lambda d: self.css('#advice-now[data-status="done"]'), "the advice", 2 * self.timeout)
        advice = self.css("#advice-now")[0].text
        self.assertRegex(advice, r"String \w+: action at fret 12 now")
        self.assertIn("Relief (gap at fret", advice)
        self.shoot(self.css("#advice-panel")[0], "advice")

        self.css("#dress")[0].click()
        self.wait(lambda d: self.css('#dress-now[data-status="done"]'), "the fret dress", 2 * self.timeout)
        self.assertRegex(self.css("#dress-now")[0].text, r"take off|Nothing to take off")
        self.shoot(self.css("#dress-panel")[0], "dress")

        self.css("#export")[0].click()
        link = self.wait(lambda d: self.css("#report-link"), "the report")[0]
        status, kind, data = self.fetch(link.get_attribute("href"))
        self.assertEqual(status, 200)
        self.assertTrue(kind.startswith("text/html"))
        html = data.decode()
        self.assertIn("data:audio/ogg;base64,", html)
        self.assertLess(len(data), 2_000_000)
        self.assertIn("Relief (gap at fret", html)  # the advice
        self.assertIn("vertical scale exaggerated", html)
        for part in ("As found", "Recommended", "After", "Dated "):
            self.assertIn(part, html)
        d.get(link.get_attribute("href"))
        self.wait(lambda d: self.css("#found"), "the report in the browser")
        self.shoot(None, "report")


class PlayersReportInTheBrowserTest(BrowserSession):
    """The player's report as clicks on the map, calibrated by the library, then the map and
    advice at the player's touch; the advice's tolerate box; a clicked cell plays the pluck its
    verdict rests on."""

    @classmethod
    def setUpClass(cls):
        cls.bench, cls.timeout, cls.shots = quick_bench(), 60, None
        cls.studio = RunningStudio(cls.bench, strengths="medium")
        cls.profile = tempfile.mkdtemp(prefix="fretbuzz-studio-chromium-")
        cls.driver = browser(cls.profile)

    def open_note(self, n):
        self.css(f'[id="note-{n["string"]}-{n["fret"]}-medium"]')[0].click()
        return self.wait(lambda d: self.css(f'#note-now[data-string="{n["string"]}"][data-fret="{n["fret"]}"]'),
                         f"note {n['string']}{n['fret']}")[0]

    def test_the_players_report_calibrates_the_touch_and_the_advice(self):
        d = self.driver
        d.get(self.studio.url + "/")
        self.map_done(1)
        audible = self.bench.settings["audible_dB"]
        notes = [n for n in self.studio.study.maps[1].notes if n["status"] == "ok"]
        # A note that buzzes whose first pluck (the attack itself) is not heard: the cell must
        # play the pluck its verdict rests on, which is.
        buzzing = [n for n in notes if n["verdict"] == "buzzes"]
        self.assertTrue(buzzing)
        buzzing.sort(key=lambda n: n["pluck_dB"][0] is not None and n["pluck_dB"][0] >= audible)
        note = self.open_note(buzzing[0])
        self.assertEqual(note.get_attribute("data-pluck-heard"), "buzz", buzzing[0]["pluck_dB"])
        self.assertIn("heard to buzz", note.text)
        member = int(note.get_attribute("data-member"))
        played = self.bench.note(buzzing[0]["string"], buzzing[0]["fret"], "medium", member=member)
        self.assertTrue(played["touched"] and played["buzz_dB"] >= audible)
        self.assertEqual(len(self.css("#note-now svg.contacts circle")), len(played["contacts"]))
        if member:
            self.assertIn(f"-pluck{member + 1}.wav", self.css("#note-audio")[0].get_attribute("src"))
        # The player marks it, and a quieter note, as they hear them on their instrument.
        self.css('#note-now button.heard[data-heard="buzz"]')[0].click()
        self.wait(lambda d: self.css(f'#map-now [id="note-{buzzing[0]["string"]}-{buzzing[0]["fret"]}-medium"]'
                                     '[data-heard="buzz"]'), "the mark on the map")
        quiet = min(notes, key=lambda n: n["buzz_fraction"])
        self.open_note(quiet)
        self.css('#note-now button.heard[data-heard="clean"]')[0].click()
        self.wait(lambda d: self.css('#player-now[data-rows="2"]'), "the report of two notes")
        self.assertTrue(self.css("#player")[0].get_attribute("disabled"))  # no touch before a calibration

        # Calibrate: the library's scale, its interval, the statement; then the map and advice at that touch.
        self.css("#calibrate")[0].click()
        calibration = self.wait(lambda d: self.css("#calibration"), "the calibration", 2 * self.timeout)[0]
        expected = self.bench.calibrate(self.studio.study.report_csv())
        self.assertIn(f"Attack scale {expected['attack_scale']:.2f}", calibration.text)
        self.assertIn(f"interval ({expected['attack_scale_low']:.2f}, ", calibration.text)
        self.assertIn(expected["statement"], calibration.text)
        second = self.map_done(2)
        self.assertIn(f"x{expected['attack_scale']:.2f}, the player's touch", second.text)
        advice = self.wait(lambda d: self.css('#advice-now[data-status="done"][data-map-id="2"]'), "the calibrated advice",
                           2 * self.timeout)[0]
        self.assertIn("the player's touch", advice.text)
        self.assertRegex(advice.text, r"String \w+: action at fret 12 now")
        self.assertTrue(self.css("#player")[0].is_selected())
        self.assertIsNone(self.css("#player")[0].get_attribute("disabled"))

        # The advice's tolerate box: the command line's choices, the library's message for a bad one.
        practice = fretbuzz._core._setup_tolerance(self.bench.instrument, "")
        self.assertIn(practice, self.css("#tolerate-default")[0].text)
        self.css("#tolerate")[0].send_keys("above=99")
        self.css("#advise")[0].click()
        self.wait(lambda d: self.css("#error-tolerate")[0].text, "the tolerate error")
        self.assertIn("tolerate", self.css("#error-tolerate")[0].text)
        self.css("#tolerate")[0].clear()
        self.css("#tolerate")[0].send_keys("marginal,above=15")
        self.css("#advise")[0].click()
        self.wait(lambda d: "tolerating marginal notes, notes above fret 15" in self.css("#advice-now")[0].text
                  and self.css('#advice-now[data-status="done"]'), "the advice tolerating", 2 * self.timeout)

        # A later what-if plays at the player's touch while the box is ticked.
        self.play(relief=RELIEF)
        third = self.map_done(3)
        self.assertIn("the player's touch", third.text)
        self.assertEqual(self.studio.study.maps[3].bench.attack_scale, expected["attack_scale"])


if __name__ == "__main__":
    unittest.main()
