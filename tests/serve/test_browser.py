"""`pbflow serve` in a real browser: Debian's Chromium, headless, driven by Selenium, against a
real server on lavapipe (docs/serve.md). The page loads; the picture changes over time; pause
holds the frame counter and resume goes on; a second viewer sees the same run; a drag turns the
view, and one on an obstacle moves it; a block lifted and let go falls back; the shake and tilt controls move the tank; a method switch shows in the stats; the measured
latency (drawn to shown) and bit rate of the H.264 stream are reported; the live charts draw. With SCREENSHOT=PATH it leaves the page's
screenshot there (the README's picture).

Usage: test_browser.py PBFLOW_BINARY (run by ctest). Prints "N passed, N failed"."""
import http.server
import os
import statistics
import sys
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_support import Client, Server  # noqa: E402

if len(sys.argv) > 1:
    os.environ["PBFLOW_BINARY"] = sys.argv.pop(1)

# What the test needs beyond pbflow: where any is missing it says so in one line and exits 77,
# which ctest reports as skipped.
MISSING = [path for path in ("/usr/bin/chromium", "/usr/bin/chromedriver") if not os.path.exists(path)]
try:
    import selenium  # noqa: F401
except ImportError:
    MISSING.append("python3-selenium")
if MISSING:
    print(f"skipped: {', '.join(MISSING)} missing (scripts/setup.sh --test installs chromium, chromium-driver and "
          "python3-selenium)")
    sys.exit(77)

from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402


def wait_for(predicate, timeout=60, what="a condition"):
    end = time.time() + timeout
    while time.time() < end:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def open_page(port, address=None):
    """Debian's Chromium, headless, on the server's page (or at `address`)."""
    options = webdriver.ChromeOptions()
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=960,720"):
        options.add_argument(flag)
    options.binary_location = "/usr/bin/chromium"
    browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    browser.get(address or f"http://127.0.0.1:{port}/")
    return browser


class PageTest(unittest.TestCase):
    """A test class's server (its SCENE and OPTIONS) and the page open on it, for all its tests."""
    SCENE, OPTIONS = "dam_break", ()

    @classmethod
    def setUpClass(cls):
        cls.server = Server(cls.SCENE, cls.OPTIONS)
        cls.browser = open_page(cls.server.port)

    @classmethod
    def tearDownClass(cls):
        cls.browser.quit()
        cls.server.stop()


class BrowserTest(PageTest):
    OPTIONS = ("--param", "particle_spacing=0.04", "--width", "480", "--height", "270")

    def live(self, key):
        return self.browser.execute_script(f"return window.pbflowLive.{key};")

    def test_1_the_page_shows_the_fluid_moving(self):
        wait_for(lambda: self.live("frames") >= 5, what="five frames on screen")
        view = self.browser.find_element("id", "view")
        first = view.screenshot_as_png
        frame = self.live("frame")
        wait_for(lambda: self.live("frame") >= frame + 10, what="ten more frames")
        self.assertNotEqual(view.screenshot_as_png, first, "the picture did not change")
        stats = self.browser.find_element("id", "stats").text
        self.assertIn("mean compression", stats)
        self.assertIn("pbf@2", stats)
        # The live charts draw the measures: a canvas with lines on it is not blank.
        blank = self.browser.execute_script(
            "const c = document.getElementById('chart-compression'), empty = document.createElement('canvas');"
            "empty.width = c.width; empty.height = c.height; return c.toDataURL() === empty.toDataURL();")
        self.assertFalse(blank, "the compression chart is blank")
        if os.environ.get("SCREENSHOT"):
            self.browser.save_screenshot(os.environ["SCREENSHOT"])

    def test_2_pause_holds_the_frame_counter_and_resume_goes_on(self):
        wait_for(lambda: self.live("frames") >= 1, what="a frame")
        self.browser.find_element("id", "pause").click()
        time.sleep(2)  # the frames drawn before the pause reach the page
        held = self.live("frame")
        time.sleep(2)
        self.assertEqual(self.live("frame"), held, "frames went on while paused")
        self.browser.find_element("id", "resume").click()
        wait_for(lambda: self.live("frame") > held + 3, what="frames after resume")

    def test_3_a_second_viewer_sees_the_same_run(self):
        other = Client(self.server.port)
        number = other.frame()[0]
        self.assertLess(abs(number - self.live("frame")), 30)
        other.sock.close()

    def test_5_a_drag_turns_the_view(self):
        self.browser.find_element("id", "pause").click()
        view = self.browser.find_element("id", "view")
        time.sleep(2)
        held, before = self.live("frame"), view.screenshot_as_png
        ActionChains(self.browser).move_to_element(view).click_and_hold().move_by_offset(120, 40).release().perform()
        wait_for(lambda: self.live("frame") > held, what="the turned view drawn")
        time.sleep(0.5)
        self.assertNotEqual(view.screenshot_as_png, before, "the drag did not change the view")
        self.browser.find_element("id", "resume").click()

    def test_6_a_method_switch_shows_in_the_stats(self):
        Select(self.browser.find_element("id", "method")).select_by_visible_text("ldc")
        wait_for(lambda: "ldc@2" in self.browser.find_element("id", "stats").text, what="ldc@2 in the stats")
        Select(self.browser.find_element("id", "iterations")).select_by_visible_text("1")
        wait_for(lambda: "ldc@1" in self.browser.find_element("id", "stats").text, what="ldc@1 in the stats")

    def test_7_another_scene_from_the_page(self):
        Select(self.browser.find_element("id", "scene")).select_by_visible_text("hydrostatic")
        wait_for(lambda: "hydrostatic" in self.browser.find_element("id", "about").text, what="hydrostatic running")
        Select(self.browser.find_element("id", "scene")).select_by_visible_text("dam_break")
        wait_for(lambda: "dam_break" in self.browser.find_element("id", "about").text, what="dam_break again")

    def test_8_a_frame_budget_from_the_page_shows_its_setting_and_front(self):
        budget = self.browser.find_element("id", "budget")

        def type_budget(ms):
            # Focused first: the page updates an unfocused field from the stats, which could
            # land between clearing it and typing (a busy machine made "0" into "400").
            budget.click()
            budget.send_keys(Keys.CONTROL, "a")
            budget.send_keys(ms, Keys.TAB)

        type_budget("40")
        text = wait_for(lambda: (lambda t: "frame budget 40 ms" in t and t)(self.browser.find_element("id", "stats").text),
                        what="the budget's front in the stats")
        self.assertRegex(text, r"(pbf|ldc)@\d/\d+ [\d.]+ ms [\d.]+ %")
        type_budget("0")
        wait_for(lambda: "frame budget" not in self.browser.find_element("id", "stats").text, what="the budget off")

    def test_4_latency_and_bit_rate_are_reported(self):
        self.browser.execute_script("window.pbflowLive.bytes = 0; window.pbflowLive.since = performance.now();"
                                    "window.pbflowLive.latencyMs = [];")
        time.sleep(5)
        seconds = (self.browser.execute_script("return performance.now();") - self.live("since")) / 1000
        latency = self.live("latencyMs")
        self.assertTrue(latency, "no frame shown in 5 s")
        # Debian's Chromium decodes H.264 through WebCodecs on loopback: the page takes the video stream.
        self.assertEqual(self.live("codec"), "h264")
        print(f"\n  {len(latency)} {self.live('codec')} frames in {seconds:.1f} s at 480x270 (dam break, lavapipe): drawn to shown "
              f"median {statistics.median(latency):.0f} ms, 90th percentile "
              f"{sorted(latency)[int(0.9 * (len(latency) - 1))]:.0f} ms; "
              f"{8 * self.live('bytes') / seconds / 1e6:.2f} Mbit/s")
        self.assertTrue(all(x >= -5 for x in latency), "a frame shown before it was drawn: clocks disagree")


class SolidsBrowserTest(PageTest):
    """A viewer moves the box of dam_obstacle by dragging it, and shakes and tilts the tank from the
    page: the server's stats show the box where the drag put it and the shaking and tilt doing work."""
    SCENE = "dam_obstacle"
    OPTIONS = ("--param", "particle_spacing=0.05", "--style", "particles", "--width", "480", "--height", "270")

    def stats(self):
        return self.browser.execute_script("return window.pbflowLive.stats;")

    def test_a_drag_on_the_box_moves_it(self):
        first = wait_for(lambda: (lambda m: m and m["solids"] and m)(self.stats()), what="the solids in the stats")
        self.assertIn("drag a solid", self.browser.find_element("id", "hint").text)
        box = first["solids"][0]
        view = self.browser.find_element("id", "view")
        size = view.size
        # From the box's middle in the picture (offsets from the element's centre), 60 px left.
        at = ((box["screen"][0] - 0.5) * size["width"], (box["screen"][1] - 0.5) * size["height"])
        ActionChains(self.browser).move_to_element_with_offset(view, int(at[0]), int(at[1])).click_and_hold() \
            .move_by_offset(-30, 0).move_by_offset(-30, 0).release().perform()
        expected = box["centre"][0] - 60 / size["width"] * size["width"] / size["height"] * box["span"]
        moved = wait_for(lambda: (lambda m: abs(m["solids"][0]["centre"][0] - expected) < 0.02 and m)(self.stats()),
                         what=f"the box's middle at x = {expected:.3f}")
        self.assertAlmostEqual(moved["solids"][0]["centre"][1], box["centre"][1], delta=0.02, msg="moved off the drag's line")

    def test_the_shake_control_shakes_the_tank(self):
        Select(self.browser.find_element("id", "shake")).select_by_visible_text("1 cm")
        shaking = wait_for(lambda: (lambda m: m and m["shake"] and m)(self.stats()), what="the shaking in the stats")
        self.assertEqual(shaking["shake"]["amplitude"], 0.01)
        self.assertEqual(shaking["shake"]["axis"], [1, 0, 0])
        self.assertGreater(shaking["shake"]["period"], 0.5, "not the tank's first sloshing mode")
        wait_for(lambda: "shaken 10 mm" in self.browser.find_element("id", "stats").text, what="the shaking in the page's text")
        wait_for(lambda: abs(self.stats()["solid_work"]) > 0, what="the shaking's work in a frame's stats")
        Select(self.browser.find_element("id", "shake")).select_by_visible_text("off")
        wait_for(lambda: self.stats()["shake"] is None, what="the shaking off")

    def test_the_tilt_control_tilts_the_tank(self):
        Select(self.browser.find_element("id", "tilt")).select_by_visible_text("10°")
        tilted = wait_for(lambda: (lambda m: m and m["tilt"] and m)(self.stats()), what="the tilt in the stats")
        self.assertEqual(tilted["tilt"], {"angle": 10, "axis": [0, 0, 1]})
        wait_for(lambda: "tilted 10°" in self.browser.find_element("id", "stats").text, what="the tilt in the page's text")
        wait_for(lambda: abs(self.stats()["solid_work"]) > 0, what="the turn's work in a frame's stats")
        Select(self.browser.find_element("id", "tilt")).select_by_visible_text("level")
        wait_for(lambda: self.stats()["tilt"] is None, what="the tank level again")


class BodiesBrowserTest(PageTest):
    """A viewer lifts a block of `floating` out of the water by dragging it and lets it go: the
    server's stats show it held where the hand put it, then falling back."""
    SCENE = "floating"
    OPTIONS = ("--param", "particle_spacing=0.04", "--style", "particles", "--width", "320", "--height", "180")

    def stats(self):
        return self.browser.execute_script("return window.pbflowLive.stats;")

    def test_a_body_lifted_and_let_go_falls_back(self):
        first = wait_for(lambda: (lambda m: m and m["solids"] and m["frame"] > 30 and m)(self.stats()),
                         what="the blocks afloat in the stats")
        self.assertIn("a body lifted and let go falls", self.browser.find_element("id", "hint").text)
        k = next(i for i, s in enumerate(first["solids"]) if s["body"] and s["span"] > 0)
        block = first["solids"][k]
        view = self.browser.find_element("id", "view")
        size = view.size
        at = ((block["screen"][0] - 0.5) * size["width"], (block["screen"][1] - 0.5) * size["height"])
        hand = ActionChains(self.browser)
        hand.move_to_element_with_offset(view, int(at[0]), int(at[1])).click_and_hold() \
            .move_by_offset(0, -20).move_by_offset(0, -20).perform()
        lifted = block["centre"][1] + 0.5 * 40 / size["height"] * block["span"]
        wait_for(lambda: self.stats()["solids"][k]["centre"][1] > lifted, what=f"the block held above y = {lifted:.3f}")
        ActionChains(self.browser).release().perform()
        wait_for(lambda: self.stats()["solids"][k]["centre"][1] < block["centre"][1] + 0.02,
                 what="the block fallen back to the water")
        # The bodies ride a shaken tank: the shake is taken, and the block rocks on the water.
        Select(self.browser.find_element("id", "shake")).select_by_visible_text("1 cm")
        wait_for(lambda: self.stats()["shake"] is not None, what="the shake taken")
        heights = []
        wait_for(lambda: heights.append(self.stats()["solids"][k]["centre"][1]) or len(heights) > 40,
                 what="the block's heights while shaken")
        self.assertLess(max(abs(h - block["centre"][1]) for h in heights), 0.03, "the block stays afloat")


class FlowBrowserTest(PageTest):
    """The fountain's tap from the page: off, no water enters while the drains go on taking it;
    on again, the jet runs."""
    SCENE = "fountain"
    OPTIONS = ("--param", "particle_spacing=0.04", "--style", "particles", "--width", "320", "--height", "180")

    def stats(self):
        return self.browser.execute_script("return window.pbflowLive.stats;")

    def test_the_tap_turns_the_emitters_off_and_on(self):
        wait_for(lambda: self.browser.find_element("id", "tap").is_displayed(), what="the tap control")
        wait_for(lambda: (lambda m: m and m["emitted"] > 0)(self.stats()), what="the jet emitting")
        Select(self.browser.find_element("id", "tap")).select_by_visible_text("off")
        wait_for(lambda: (lambda m: m and m["emitting"] is False)(self.stats()), what="the tap off in the stats")
        frame = self.stats()["frame"]
        emitted = []
        while len(emitted) < 20:  # a layer is due every 1.2 frames: 20 frames off would hold ~16
            m = wait_for(lambda: (lambda m: m and m["frame"] > frame and m)(self.stats()), what="the next frame")
            frame = m["frame"]
            emitted.append(m["emitted"])
        self.assertEqual(sum(emitted), 0, "water entered with the tap off")
        wait_for(lambda: "the tap off" in self.browser.find_element("id", "stats").text, what="the tap in the page's text")
        Select(self.browser.find_element("id", "tap")).select_by_visible_text("on")
        wait_for(lambda: (lambda m: m and m["emitting"] and m["emitted"] > 0)(self.stats()), what="the jet again")


class CompareBrowserTest(PageTest):
    OPTIONS = ("--param", "particle_spacing=0.05", "--style", "particles", "--width", "160", "--height", "90",
               "--compare", "pbf@1,ldc@1,pbf@2")

    def test_each_panel_is_labelled_with_its_setting_and_compression(self):
        # Read in one call: the page replaces the labels with every frame.
        labels = wait_for(lambda: self.browser.execute_script(
            "return [...document.querySelectorAll('#labels div')].map((e) => e.textContent);"), what="the panels' labels")
        self.assertEqual([label.split()[0] for label in labels], ["pbf@1", "ldc@1", "pbf@2"])
        for label in labels:
            self.assertRegex(label, r"[\d.]+ %$")
        self.assertFalse(self.browser.find_element("id", "method").is_enabled(), "a panel's setting is fixed")


class AnotherOriginBrowserTest(unittest.TestCase):
    """A page from another origin (a second loopback server, as any site the user opens) tries
    to open the live server's socket and steer it: refused at the handshake."""

    def test_a_page_from_another_origin_cannot_steer(self):
        server = Server()
        port = server.port

        class Attacker(http.server.BaseHTTPRequestHandler):
            def do_GET(self):
                page = (f"<script>window.result = {{opened: false, closed: false}};"
                        f"const s = new WebSocket('ws://127.0.0.1:{port}/ws');"
                        "s.onopen = () => { window.result.opened = true;"
                        "  s.send(JSON.stringify({cmd: 'scene', name: 'drop'})); s.send('\u00e9'); };"
                        "s.onclose = () => { window.result.closed = true; };</script>").encode()
                self.send_response(200)
                self.send_header("Content-Type", "text/html")
                self.send_header("Content-Length", str(len(page)))
                self.end_headers()
                self.wfile.write(page)

            def log_message(self, *args):
                pass

        attacker = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Attacker)
        threading.Thread(target=attacker.serve_forever, daemon=True).start()
        browser = open_page(port, f"http://127.0.0.1:{attacker.server_address[1]}/")
        try:
            wait_for(lambda: browser.execute_script("return window.result && window.result.closed;"),
                     what="the other origin's socket to close")
            self.assertFalse(browser.execute_script("return window.result.opened;"), "another origin opened the socket")
            time.sleep(2)
            self.assertTrue(server.alive())
            viewer = Client(port)
            for _ in range(5):
                _, _, stats = viewer.frame()
            self.assertEqual(stats["scene"], "hydrostatic", "another origin switched the scene")
            viewer.sock.close()
        finally:
            browser.quit()
            attacker.shutdown()
            server.stop()


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    failed = len(result.failures) + len(result.errors)
    print(f"{result.testsRun - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)
