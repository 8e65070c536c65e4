"""The web dashboard (served by `penumbra serve` at /) in a real browser: Debian's chromium,
headless, driven by Selenium through chromium-driver, against the real binary
($PENUMBRA_BINARY) started with a token. Run by scripts/browser-test.sh (ctest label "browser").

It submits scenes through the page's file input (what a drop does), watches a running job's
progress bar move and its live preview change, downloads the PNG through the page, cancels a
job, shows an invalid scene's field errors, and checks that the token never appears in a URL.
With $PENUMBRA_SCREENSHOT set, it saves a screenshot of the page there (docs/images/).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
import unittest
import urllib.request

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as EC
from selenium.webdriver.support.ui import WebDriverWait

BINARY = os.environ.get("PENUMBRA_BINARY", "penumbra")
TOKEN = "dashboard-test-token-5f1c"


def scene(width=96, height=72, spp=16, time_limit=0.0, seed=1):
    s = {"version": 1,
         "render": {"width": width, "height": height, "spp": spp, "seed": seed},
         "camera": {"position": [0, 0.3, 4], "look_at": [0, 0, 0], "fov": 40},
         "environment": {"radiance": [0.6, 0.7, 0.9]},
         "materials": {"red": {"type": "diffuse", "color": [0.8, 0.2, 0.1]},
                       "floor": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}},
         "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "red"},
                     {"type": "quad", "origin": [-5, -1, 5], "u": [10, 0, 0], "v": [0, 0, -10],
                      "material": "floor"}]}
    if time_limit:
        s["render"]["time_limit"] = time_limit
    return s


class Dashboard(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="penumbra-dashboard-")
        cls.downloads = os.path.join(cls.dir, "downloads")
        os.makedirs(cls.downloads)
        cls.log = open(os.path.join(cls.dir, "access.log"), "w")
        cls.server = subprocess.Popen(
            [BINARY, "serve", "--port", "0", "--data-dir", os.path.join(cls.dir, "data"),
             "--token", TOKEN, "--access-log"],
            stdout=subprocess.PIPE, stderr=cls.log, text=True)
        line = cls.server.stdout.readline()
        match = re.search(r"listening on (http://\S+)", line)
        if not match:
            raise RuntimeError(f"penumbra serve did not start: {line!r}")
        cls.url = match.group(1)
        threading.Thread(target=cls.server.stdout.read, daemon=True).start()

        options = webdriver.ChromeOptions()
        options.binary_location = os.environ.get("CHROMIUM", "/usr/bin/chromium")
        for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                    "--disable-gpu", "--window-size=1320,760"):
            options.add_argument(arg)
        options.add_experimental_option("prefs", {"download.default_directory": cls.downloads,
                                                  "download.prompt_for_download": False})
        service = Service(os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver"))
        cls.driver = webdriver.Chrome(service=service, options=options)
        cls.driver.execute_cdp_cmd("Page.setDownloadBehavior",
                                   {"behavior": "allow", "downloadPath": cls.downloads})
        cls.driver.get(cls.url + "/")
        cls.wait = WebDriverWait(cls.driver, 60, poll_frequency=0.05)
        token = cls.driver.find_element(By.ID, "token")
        token.send_keys(TOKEN)
        cls.driver.find_element(By.CSS_SELECTOR, "#token-form button").click()

    @classmethod
    def tearDownClass(cls):
        try:
            cls.driver.quit()
        finally:
            cls.server.terminate()
            cls.server.wait(timeout=20)
            cls.log.close()
            shutil.rmtree(cls.dir, ignore_errors=True)

    # -- helpers ---------------------------------------------------------------------------------
    def api(self, path):
        req = urllib.request.Request(self.url + path,
                                     headers={"Authorization": f"Bearer {TOKEN}"})
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.read()

    def submit_through_page(self, content, name="scene.json"):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))
        self.driver.execute_script("document.getElementById('message').textContent = ''")
        self.driver.find_element(By.ID, "file").send_keys(path)
        return self.wait.until(lambda d: d.find_element(By.ID, "message").text or None)

    def submitted_id(self, message):
        match = re.search(r"as ([0-9a-f]{24})", message)
        self.assertIsNotNone(match, message)
        return match.group(1)

    def row(self, job_id):
        return self.wait.until(EC.presence_of_element_located(
            (By.CSS_SELECTOR, f'tr[data-id="{job_id}"]')))

    def row_state(self, job_id):
        return self.row(job_id).find_element(By.CSS_SELECTOR, "td.state").text

    # -- tests -----------------------------------------------------------------------------------
    def test_1_a_submitted_job_shows_live_progress_and_preview_then_downloads(self):
        job_id = self.submitted_id(self.submit_through_page(scene(spp=1 << 16, time_limit=6)))
        self.wait.until(lambda d: self.row_state(job_id) == "running")
        progress, previews = set(), set()
        deadline = time.time() + 60
        while time.time() < deadline:
            state = self.driver.find_element(By.ID, "detail-state").text
            value = self.driver.find_element(By.ID, "detail-progress").get_attribute("value")
            key = self.driver.find_element(By.ID, "detail-image").get_attribute("data-key")
            if state == "running":
                progress.add(value)
                if key:
                    previews.add(key)
            if state == "succeeded":
                break
            time.sleep(0.1)
        self.assertEqual(self.row_state(job_id), "succeeded")
        self.assertGreaterEqual(len(progress), 3, f"the progress bar did not move: {progress}")
        self.assertGreaterEqual(len(previews), 2, f"the preview did not change: {previews}")
        if os.environ.get("PENUMBRA_SCREENSHOT"):
            second = self.submitted_id(self.submit_through_page(
                scene(spp=1 << 16, time_limit=20, seed=2), "second.json"))
            self.submit_through_page(scene(spp=4, seed=3), "third.json")
            self.wait.until(lambda d: self.row_state(second) == "running")
            self.row(second).click()
            time.sleep(3)
            self.driver.save_screenshot(os.environ["PENUMBRA_SCREENSHOT"])
        # Download the PNG through the page: the same bytes as the API's.
        self.row(job_id).click()
        self.wait.until(lambda d: d.find_element(By.ID, "detail-title").text == job_id)
        panel = self.driver.find_element(By.ID, "detail-actions")
        button = self.wait.until(lambda d: panel.find_elements(By.XPATH, ".//button[text()='PNG']"))
        button[0].click()
        target = os.path.join(self.downloads, f"{job_id}.png")
        deadline = time.time() + 30
        while not os.path.exists(target) and time.time() < deadline:
            time.sleep(0.1)
        self.assertTrue(os.path.exists(target), os.listdir(self.downloads))
        time.sleep(0.3)
        with open(target, "rb") as f:
            self.assertEqual(f.read(), self.api(f"/v1/jobs/{job_id}/result?format=png"))

    def test_2_cancel_from_the_page(self):
        job_id = self.submitted_id(self.submit_through_page(scene(spp=1 << 16, time_limit=600)))
        row = self.row(job_id)
        self.wait.until(lambda d: row.find_elements(By.XPATH, ".//button[text()='Cancel']"))
        row.find_element(By.XPATH, ".//button[text()='Cancel']").click()
        self.wait.until(lambda d: self.row_state(job_id) == "cancelled")
        record = json.loads(self.api(f"/v1/jobs/{job_id}"))
        self.assertEqual(record["state"], "cancelled")

    def test_3_an_invalid_scene_shows_the_fields_at_fault(self):
        bad = scene()
        bad["render"]["width"] = -3
        message = self.submit_through_page(bad, "bad.json")
        self.assertIn("422", message)
        self.assertIn("/render/width", message)
        self.assertIn("error", self.driver.find_element(By.ID, "message").get_attribute("class"))

    def test_4_the_token_never_appears_in_a_url(self):
        urls = self.driver.execute_script(
            "return performance.getEntries().map(e => e.name).concat([location.href]);")
        self.assertTrue(any("/v1/jobs" in u for u in urls), urls)
        for u in urls:
            self.assertNotIn(TOKEN, u)
        with open(os.path.join(self.dir, "access.log")) as f:
            log = f.read()
        self.assertNotIn(TOKEN, log)
        # The page itself works without a token; the API does not.
        with urllib.request.urlopen(self.url + "/", timeout=10) as r:
            self.assertIn(b"penumbra", r.read())
        with self.assertRaises(urllib.error.HTTPError) as caught:
            urllib.request.urlopen(self.url + "/v1/jobs", timeout=10)
        self.assertEqual(caught.exception.code, 401)


if __name__ == "__main__":
    unittest.main()
