"""kinbench's index.html in a real headless Chromium (Debian's chromium + chromium-driver):
the leaderboard table is rendered, a header click sorts its rows, the figures are shown.
CI installs them with: apt-get install -y chromium chromium-driver."""
import shutil
import tempfile
from pathlib import Path

import pytest

from test_kinbench import tiny

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed (pip install selenium)")
pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(not (CHROMIUM and DRIVER),
                                 reason="needs Debian's chromium and chromium-driver "
                                        "(apt-get install -y chromium chromium-driver)")]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    from fkopt.run.pipeline import load_any, run_config
    tmp = tmp_path_factory.mktemp("kb")
    path = tiny(tmp)
    folder = run_config(load_any(path), tmp / "out", source=str(path)).folder
    return folder / "index.html"


@pytest.fixture(scope="module")
def browser():
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
    profile = tempfile.mkdtemp(prefix="kb-chromium-")
    opts = Options()
    opts.binary_location = CHROMIUM
    for arg in ("--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", f"--user-data-dir={profile}",
                "--window-size=1280,2000"):
        opts.add_argument(arg)
    drv = webdriver.Chrome(service=Service(DRIVER), options=opts)
    yield drv
    drv.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _column(table, name):
    from selenium.webdriver.common.by import By
    heads = [th.text.strip() for th in table.find_elements(By.CSS_SELECTOR, "thead th")]
    j = heads.index(name)
    return [tr.find_elements(By.TAG_NAME, "td")[j].text for tr in table.find_elements(By.CSS_SELECTOR, "tbody tr")]


def test_the_leaderboard_renders_sorts_and_shows_its_figures(page, browser):
    from selenium.webdriver.common.by import By
    browser.get(page.as_uri())
    table = browser.find_element(By.ID, "leaderboard")
    assert table.is_displayed()
    solvers = _column(table, "solver")
    assert sorted(solvers) == ["lm", "pso"]
    ranks = _column(table, "rank")
    assert ranks == sorted(ranks, key=int)
    header = next(th for th in table.find_elements(By.CSS_SELECTOR, "thead th") if th.text.strip() == "solver")
    header.click()
    assert _column(table, "solver") == ["lm", "pso"]
    header.click()
    assert _column(table, "solver") == ["pso", "lm"]
    score = next(th for th in table.find_elements(By.CSS_SELECTOR, "thead th") if th.text.strip() == "score")
    score.click()
    values = [float(v) for v in _column(table, "score")]
    assert values == sorted(values)
    images = browser.find_elements(By.CSS_SELECTOR, "figure img")
    assert len(images) >= 2          # all problems + one per class
    for img in images:              # decoded and laid out: the data URI is a real picture
        assert browser.execute_script("return arguments[0].complete && arguments[0].naturalWidth", img) > 100
        assert img.is_displayed() and img.size["width"] > 100
    assert browser.execute_script(
        "return performance.getEntriesByType('resource').filter(e => !e.name.startsWith('data:')).length") == 0
