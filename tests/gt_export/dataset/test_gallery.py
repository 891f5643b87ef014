"""The gallery's index, contact sheets and page; the page used like a person in headless Chromium."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.gt_export import build_gallery, export_sample, load_sample
from spectrinsic.gt_export.dataset.contact_sheet import COLUMNS, TILE
from spectrinsic.gt_export.dataset.gallery import INDEX_VARIABLE, gallery_index

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")
HAVE_SELENIUM = importlib.util.find_spec("selenium") is not None
#: The browser tests run where Chromium, its WebDriver and Selenium are installed.
needs_browser = pytest.mark.skipif(
    CHROMIUM is None or CHROMEDRIVER is None or not HAVE_SELENIUM,
    reason="headless Chromium, chromium-driver or selenium not installed (scripts/setup-system.sh "
    "installs the Debian packages chromium and chromium-driver, `make setup` selenium)",
)
#: Seconds the browser may take to show an element (it starts in ~1 s here).
BROWSER_WAIT_S = 20
#: Slack on top of a preview's stated precision (float32 EXR vs float64 decoding in the page).
READOUT_SLACK = 1e-6
#: Conditions of the three synthetic samples.
CONDITIONS = {"one": "white", "two": "two-colour-a", "three": "white"}


@pytest.fixture
def dataset(tmp_path, one_light_sample, two_light_sample, config):
    """Three exported samples in two conditions, with a manifest that has splits."""
    samples = {"one": one_light_sample, "two": two_light_sample, "three": one_light_sample}
    for sid, (scene, result) in samples.items():
        meta = {**scene.metadata, "condition": CONDITIONS[sid], "kind": "object"}
        export_sample(
            tmp_path / "ds",
            dataclasses.replace(scene, metadata=meta),
            result,
            sample_id=sid,
            config=config,
            seed=1,
        )
    root = tmp_path / "ds"
    (root / "manifest.json").write_text(
        json.dumps({"splits": {"train": ["one", "two"], "test": ["three"]}})
    )
    return root


@pytest.fixture
def gallery(dataset):
    return build_gallery(dataset)


def _script_index(root: Path) -> dict:
    text = (root / "gallery-index.js").read_text()
    prefix = f"window.{INDEX_VARIABLE} = "
    assert text.startswith(prefix)
    return json.loads(text[len(prefix) :].rstrip().rstrip(";"))


def test_index_records_every_sample_with_its_previews_and_encodings(gallery):
    root = gallery.parent
    index = json.loads((root / "gallery.json").read_text())
    assert _script_index(root) == index  # the page's script holds the same index
    assert [s["id"] for s in index["samples"]] == ["one", "three", "two"]
    by_id = {s["id"]: s for s in index["samples"]}
    assert {s: by_id[s]["split"] for s in by_id} == {
        "one": "train",
        "two": "train",
        "three": "test",
    }
    assert index["splits"] == ["test", "train"]
    for sid, entry in by_id.items():
        meta = json.loads((root / sid / "meta.json").read_text())
        assert entry["condition"] == CONDITIONS[sid]
        assert (
            entry["generator"] == "own scene"
        )  # the synthetic scenes name no library or generator
        for name, rec in meta["layers"].items():
            if rec["preview"]:
                src, enc = entry["layers"][name]
                assert src == f"{sid}/{rec['preview']}" and (root / src).is_file()
                assert enc == rec["preview_encoding"]
        assert len(entry["lights"]) == len(meta["lights"]) and len(entry["lights"][0]["spd"]) == 81
        assert all((root / f).is_file() for f in entry["files"])
        pixels = (root / entry["pixels"]).read_text()
        assert pixels.count("data:image/png;base64,") == sum(
            enc["kind"] != "categorical" for _, enc in entry["layers"].values()
        )
    for name, lut in index["colormaps"].items():
        assert len(lut) == 256, name
    # the locus starts in the violet corner (x≈0.17, y≈0.005) and passes near the green peak
    locus = np.asarray(index["locus"])
    assert locus[0] == pytest.approx([0.1741, 0.0050], abs=2e-3)
    assert locus[:, 1].max() == pytest.approx(0.834, abs=5e-3)


def test_contact_sheets_per_condition(gallery):
    from PIL import Image

    root = gallery.parent
    index = json.loads((root / "gallery.json").read_text())
    assert set(index["contact_sheets"]) == {"all", "white", "two-colour-a"}
    with Image.open(root / index["contact_sheets"]["white"]) as img:
        assert img.width == 2 * TILE  # two samples in the white condition
    with Image.open(root / "contact_sheet.png") as img:
        assert img.width == min(3, COLUMNS) * TILE


def test_index_without_splits_or_a_manifest(dataset):
    (dataset / "manifest.json").unlink()
    index = gallery_index(dataset)
    assert index["splits"] == [] and {s["split"] for s in index["samples"]} == {None}


# ----------------------------------------------------------------------------------------------
# In the browser


def _driver(screenshots: Path, *, file_access: bool = False):
    """A headless Chromium WebDriver that keeps the browser's console log; *file_access* lets
    file:// pages read their own images (by default, as for a person, they may not)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--window-size=1400,1000",
    ):
        options.add_argument(arg)
    if file_access:
        options.add_argument("--allow-file-access-from-files")
    options.binary_location = CHROMIUM or ""
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    screenshots.mkdir(exist_ok=True)
    return webdriver.Chrome(service=Service(CHROMEDRIVER or ""), options=options)


def _errors(driver) -> list[str]:
    return [e["message"] for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]


def _pixel_report(driver, element, dx: int, dy: int, layers: tuple[str, ...]) -> dict:
    """Move the mouse to (dx, dy) from *element*'s centre; return the readout's report once it
    holds *layers* (pixel values may load after the first move)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.support.ui import WebDriverWait

    ActionChains(driver).move_to_element_with_offset(element, dx, dy).perform()

    def ready(d):
        report = json.loads(d.find_element("id", "readout").get_attribute("data-report") or "{}")
        return report if set(layers) <= set(report.get("layers", {})) else False

    return WebDriverWait(driver, BROWSER_WAIT_S).until(
        ready, driver.find_element("id", "readout").text
    )


def _check_readout_against_exr(
    report: dict, root: Path, sample: str, layer: str, info: dict
) -> int:
    """Assert the readout of *layer* matches the EXR pixel (of the sRGB view the previews
    show: the sample's working space is ACEScg) within its stated precision; return how many
    channels were inside the encoded range (and so compared to a value)."""
    exr = load_sample(root / sample, layers=[layer], space="srgb")[layer]
    truth = np.atleast_1d(exr[report["y"], report["x"]])
    shown = report["layers"][layer]
    compared = 0
    rows = zip(shown["values"], shown["precision"], shown["clipped"], shown["under"], truth)
    for value, precision, clipped, under, true in rows:
        if clipped:  # saturated: the page says "≥ clip"
            assert true >= value - precision - READOUT_SLACK
        elif under:  # code 0: the page says "≤ precision" (negative values clip to 0)
            assert true <= value + precision + READOUT_SLACK
        else:
            assert abs(true - value) <= precision + READOUT_SLACK, (layer, report, float(true))
            compared += 1
    return compared


@pytest.mark.browser
@needs_browser
def test_a_person_filters_opens_a_sample_and_reads_a_pixel(gallery, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support import expected_conditions as ec
    from selenium.webdriver.support.select import Select
    from selenium.webdriver.support.ui import WebDriverWait

    root, shots = gallery.parent, tmp_path / "screenshots"
    driver = _driver(shots)
    try:
        wait = WebDriverWait(driver, BROWSER_WAIT_S)
        driver.get(gallery.as_uri())
        wait.until(lambda d: len(d.find_elements("css selector", ".card")) == 3)
        driver.save_screenshot(str(shots / "overview.png"))
        assert _errors(driver) == []
        # filter to one condition
        Select(driver.find_element("id", "filter-condition")).select_by_value("white")
        cards = [c.get_attribute("data-id") for c in driver.find_elements("css selector", ".card")]
        assert cards == ["one", "three"]
        # open a sample
        driver.find_element("css selector", '.card[data-id="one"]').click()
        wait.until(ec.presence_of_element_located(("id", "sample")))
        image = driver.find_element("css selector", "#viewer img.a")
        wait.until(lambda d: d.execute_script("return arguments[0].naturalWidth", image) > 0)
        assert len(driver.find_elements("css selector", "#lights svg.spd")) == 1
        # click to zoom: the image doubles in size
        width = image.size["width"]
        driver.find_element("id", "viewer").click()
        assert image.size["width"] == 2 * width
        viewer = driver.find_element("id", "viewer")
        ActionChains(driver).key_down(Keys.SHIFT).click(viewer).key_up(
            Keys.SHIFT
        ).perform()  # zoom out
        assert image.size["width"] == width
        assert len(driver.find_elements("css selector", "#lights circle.light-dot")) == 1
        # switch layers: A to the error map (a colour bar appears), back to the image
        driver.find_element(
            "css selector",
            '#layers button[data-layer="noise_image"], #layers button[data-layer="depth"]',
        ).click()
        assert driver.find_elements("css selector", "#colourbars canvas")
        layer_a = driver.execute_script(
            "return document.querySelector('#layers button.on').dataset.layer"
        )
        assert image.get_attribute("src").endswith(f"previews/{layer_a}.png")
        driver.find_element("css selector", '#layers button[data-layer="image"]').click()
        Select(driver.find_element("id", "layer-b")).select_by_value("reflectance")
        # move the A/B slider: B's clip follows it
        slider = driver.find_element("id", "ab-slider")
        before = driver.find_element("css selector", "#viewer img.b").value_of_css_property(
            "clip-path"
        )
        ActionChains(driver).click_and_hold(slider).move_by_offset(
            -slider.size["width"] // 3, 0
        ).release().perform()
        after = driver.find_element("css selector", "#viewer img.b").value_of_css_property(
            "clip-path"
        )
        assert before != after and float(slider.get_attribute("value")) < 40
        driver.save_screenshot(str(shots / "sample-ab.png"))
        # read pixels: the image and reflectance values match the EXR within the stated precision
        info = json.loads((root / "gallery.json").read_text())["layer_info"]
        compared = 0
        for dx, dy in ((-60, -40), (60, -40), (-60, 60), (60, 60)):
            report = _pixel_report(driver, image, dx, dy, ("image", "reflectance"))
            assert report["source"] == "embedded"  # file:// images are not readable in Chromium
            for layer in ("image", "reflectance"):
                compared += _check_readout_against_exr(report, root, "one", layer, info[layer])
        assert compared >= 8
        # an error map (a colormap preview) reads back too, in the other condition's sample
        driver.execute_script("location.hash = 'sample=two'")
        wait.until(lambda d: d.find_element("id", "sample").get_attribute("data-id") == "two")
        driver.find_element("css selector", '#layers button[data-layer="error_rgb3"]').click()
        image = driver.find_element("css selector", "#viewer img.a")
        wait.until(
            lambda d: d.execute_script(
                "return arguments[0].complete && arguments[0].naturalWidth", image
            )
        )
        compared = sum(
            _check_readout_against_exr(
                _pixel_report(driver, image, dx, dy, ("error_rgb3",)),
                root,
                "two",
                "error_rgb3",
                info["error_rgb3"],
            )
            for dx, dy in ((-60, -40), (60, -40), (-60, 60), (60, 60))
        )
        assert compared >= 1
        assert _errors(driver) == []
    finally:
        driver.quit()


@pytest.mark.browser
@needs_browser
def test_the_readout_check_can_fail(gallery, tmp_path):
    """A preview whose stated scale is wrong gives readouts the EXR check rejects (read from the
    PNG files themselves, as a served page or a permissive browser does)."""
    root = gallery.parent
    index_js = root / "gallery-index.js"
    index = _script_index(root)
    sample = next(s for s in index["samples"] if s["id"] == "one")
    sample["layers"]["image"][1]["scale"] *= 2.0
    index_js.write_text(f"window.{INDEX_VARIABLE} = {json.dumps(index)};\n")
    driver = _driver(tmp_path / "screenshots", file_access=True)
    try:
        driver.get(gallery.as_uri() + "#sample=one")
        image = driver.find_element("css selector", "#viewer img.a")
        from selenium.webdriver.support.ui import WebDriverWait

        WebDriverWait(driver, BROWSER_WAIT_S).until(
            lambda d: d.execute_script("return arguments[0].naturalWidth", image) > 0
        )
        report = _pixel_report(driver, image, -60, -40, ("image",))
        assert report["source"] == "file"  # this browser may read the previews themselves
        with pytest.raises(AssertionError):
            _check_readout_against_exr(report, root, "one", "image", index["layer_info"]["image"])
    finally:
        driver.quit()


def test_a_users_file_in_gallery_pixels_survives_a_rebuild(gallery):
    root = gallery.parent
    pixels = root / "gallery-pixels"
    (pixels / "notes.txt").write_text("mine")
    (pixels / "mine.js").write_text("console.log('mine')\n")
    shutil.rmtree(root / "three")  # a sample gone: its script (ours) goes with it
    build_gallery(root)
    assert (pixels / "notes.txt").read_text() == "mine"
    assert (pixels / "mine.js").read_text() == "console.log('mine')\n"
    assert sorted(p.name for p in pixels.glob("*.js")) == ["mine.js", "one.js", "two.js"]


def test_a_full_disk_while_writing_the_gallery_names_the_file(gallery, monkeypatch):
    import errno

    from spectrinsic.errors import DiskFullError

    real = Path.write_text

    def full(self, *args, **kwargs):
        if self.name.endswith("gallery.json"):  # the temporary renamed over it
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(DiskFullError, match=r"gallery\.json.*No space left"):
        build_gallery(gallery.parent)


def test_a_script_tag_in_a_scene_name_is_escaped_in_the_card(tmp_path, one_light_sample, config):
    from spectrinsic.gt_export import write_dataset_card, write_manifest

    scene, result = one_light_sample
    evil = dataclasses.replace(scene, name="<script>alert(1)</script>")
    export_sample(tmp_path, evil, result, sample_id="s", config=config, seed=1)
    write_manifest(tmp_path, config)
    card = write_dataset_card(tmp_path, config).read_text(encoding="utf-8")
    assert "<script>" not in card
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in card


@pytest.fixture
def denoised_gallery(tmp_path, one_light_sample, two_light_sample, config):
    """Two samples exported with the OIDN-denoised shading (so with ``image_denoised``) and one
    without, and their gallery."""
    root = tmp_path / "dn"
    for sid, (scene, result), denoise in (
        ("a", two_light_sample, True),
        ("b", one_light_sample, True),
        ("c", one_light_sample, False),
    ):
        meta = {**scene.metadata, "condition": "white", "kind": "object"}
        export_sample(
            root,
            dataclasses.replace(scene, metadata=meta),
            result,
            sample_id=sid,
            config=config,
            seed=1,
            denoise=denoise,
        )
    return build_gallery(root)


def test_index_opens_on_the_denoised_image_with_kind_shares_and_neighbours(denoised_gallery):
    """Issue 19: image_denoised first where it exists, kind and light shares for every sample,
    previous/next between samples."""
    root = denoised_gallery.parent
    index = json.loads((root / "gallery.json").read_text())
    ids = [s["id"] for s in index["samples"]]
    for i, entry in enumerate(index["samples"]):
        meta = json.loads((root / entry["id"] / "meta.json").read_text())
        names = list(entry["layers"])
        first = "image_denoised" if entry["id"] != "c" else "image"
        assert ("image_denoised" in meta["layers"]) == (entry["id"] != "c")
        assert names[0] == entry["first_layer"] == first
        assert entry["kind"] == "object"
        assert entry["light_shares"] == [light["share"] for light in meta["lights"]]
        assert sum(entry["light_shares"]) == pytest.approx(
            1.0, abs=1e-3
        )  # shares of the irradiance
        assert entry["prev"] == (ids[i - 1] if i else None)
        assert entry["next"] == (ids[i + 1] if i + 1 < len(ids) else None)


@pytest.mark.parametrize(
    ("metadata", "kind"),
    [
        ({"generator": "rooms"}, "complex"),
        ({"generator": "objects-on-ground"}, "object"),
        ({}, "complex"),
    ],
)
def test_a_sample_without_kind_metadata_still_has_a_kind(
    tmp_path, one_light_sample, config, metadata, kind
):
    scene, result = one_light_sample
    export_sample(
        tmp_path / "ds",
        dataclasses.replace(scene, name="mine", metadata=metadata),
        result,
        sample_id="mine__v0__file",
        config=config,
        seed=1,
    )
    (entry,) = gallery_index(tmp_path / "ds")["samples"]
    assert entry["kind"] == kind and entry["light_shares"] and None not in entry["light_shares"]


@pytest.mark.browser
@needs_browser
def test_a_person_steps_between_samples_and_sees_every_layer(denoised_gallery, tmp_path):
    from selenium.webdriver.support.ui import WebDriverWait

    gallery = denoised_gallery
    root = gallery.parent
    index = json.loads((root / "gallery.json").read_text())
    first = index["samples"][0]
    driver = _driver(tmp_path / "screenshots")
    try:
        wait = WebDriverWait(driver, BROWSER_WAIT_S)
        driver.get(gallery.as_uri() + "#sample=" + first["id"])
        wait.until(lambda d: d.find_elements("id", "sample"))
        image = driver.find_element("css selector", "#viewer img.a")
        assert image.get_attribute("src").endswith("previews/image_denoised.png")
        assert "light shares" in driver.find_element("id", "sample-meta").text
        tiles = driver.find_elements("css selector", "#layer-grid figure")
        assert [t.get_attribute("data-layer") for t in tiles] == list(first["layers"])
        tiles[-1].click()  # a tile shows its layer as A
        assert image.get_attribute("src").endswith(
            first["layers"][list(first["layers"])[-1]][0].split("/", 1)[1]
        )
        assert not driver.find_elements("css selector", "a#prev-sample")  # the first has none
        driver.find_element("id", "next-sample").click()
        wait.until(
            lambda d: d.find_element("id", "sample").get_attribute("data-id") == first["next"]
        )
        driver.find_element("id", "prev-sample").click()
        wait.until(lambda d: d.find_element("id", "sample").get_attribute("data-id") == first["id"])
        assert _errors(driver) == []
    finally:
        driver.quit()
