"""The HTML gallery and contact sheet; the page checked in headless Chromium."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from spectrinsic.gt_export import build_gallery, export_sample
from spectrinsic.gt_export.gallery import TILE, chromaticity_svg

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: Seconds Chromium may take to load the page (it starts in ~1 s here).
BROWSER_TIMEOUT_S = 90


class _Images(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.srcs: list[str] = []
        self.svgs = 0

    def handle_starttag(self, tag, attrs):
        if tag == "img":
            self.srcs.append(dict(attrs)["src"])
        if tag == "svg":
            self.svgs += 1


@pytest.fixture
def gallery(tmp_path, one_light_sample, two_light_sample, config):
    for sid, (scene, result) in (("one", one_light_sample), ("two", two_light_sample)):
        export_sample(tmp_path, scene, result, sample_id=sid, config=config, seed=1)
    return build_gallery(tmp_path)


def test_every_sample_has_its_layers_and_a_chromaticity_diagram(gallery):
    root = gallery.parent
    parser = _Images()
    parser.feed(gallery.read_text())
    for sample in ("one", "two"):
        meta = json.loads((root / sample / "meta.json").read_text())
        for key in ("image", "reflectance", "shading", "illuminant", "depth", "normals"):
            assert f"{sample}/{meta['layers'][key]['preview']}" in parser.srcs
    assert all((root / src).is_file() for src in parser.srcs)
    assert parser.svgs == 2
    sheet = root / "contact_sheet.png"
    from PIL import Image

    with Image.open(sheet) as img:
        assert img.width == 2 * TILE


def test_light_dots_sit_at_their_chromaticities():
    svg = chromaticity_svg([
        {"xy": (0.3127, 0.3290), "srgb": (1.0, 1.0, 1.0), "spectrum": "cie:D65", "name": "a"},
        {"xy": (0.4476, 0.4074), "srgb": (1.0, 0.7, 0.3), "spectrum": "cie:A", "name": "b"},
    ])
    dots = [(float(x), float(y)) for x, y in re.findall(r'<circle cx="([\d.]+)" cy="([\d.]+)" r="5"', svg)]
    assert len(dots) == 2
    (xa, ya), (xb, yb) = dots
    assert xb > xa and yb < ya  # A is right of and (in SVG coordinates) above D65
    # positions are linear in xy: Δx_svg / Δx = plot width / 0.8
    assert (xb - xa) / (0.4476 - 0.3127) == pytest.approx((200 - 2 * 22) / 0.8, rel=1e-2)
    assert "cie:A" in svg and "fill=\"#ffffff\"" in svg


_PROBE = """<!DOCTYPE html><html><body><pre id="out">pending</pre>
<iframe id="f" src="index.html" width="1200" height="800"></iframe>
<script>
document.getElementById("f").addEventListener("load", () => {
  const doc = document.getElementById("f").contentDocument;
  const imgs = Array.from(doc.images);
  const bad = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute("src"));
  document.getElementById("out").textContent = JSON.stringify(
    {images: imgs.length, broken: bad, svgs: doc.querySelectorAll("svg circle[r='5']").length,
     sections: doc.querySelectorAll("section.sample").length});
});
</script></body></html>"""


def _load_in_chromium(root: Path) -> tuple[dict, list[str]]:
    """Load index.html (through a probe page) in headless Chromium; return the probe's report
    and the console messages logged by index.html."""
    (root / "probe.html").write_text(_PROBE)
    proc = subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--allow-file-access-from-files", "--enable-logging=stderr", "--v=0",
         "--virtual-time-budget=5000", "--dump-dom", (root / "probe.html").as_uri()],
        capture_output=True, text=True, timeout=BROWSER_TIMEOUT_S,
    )
    match = re.search(r'<pre id="out">(.*?)</pre>', proc.stdout, re.S)
    assert match, f"probe did not report; stderr: {proc.stderr[-2000:]}"
    console = [line for line in proc.stderr.splitlines()
               if ":CONSOLE" in line and "index.html" in line]
    report = json.loads(match.group(1).replace("&quot;", '"'))
    return report, console


@pytest.mark.browser
@pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium not installed (Debian package chromium)")
def test_gallery_loads_in_chromium_with_every_image(gallery):
    root = gallery.parent
    report, console = _load_in_chromium(root)
    assert console == []
    assert report["sections"] == 2
    assert report["broken"] == []
    assert report["images"] >= 2 * 9
    assert report["svgs"] == 1 + 2  # one dot for the one-light sample, two for the other
    # the probe does see a missing image (so the check above can fail)
    missing = root / "two" / "previews" / "normals.png"
    missing.unlink()
    report, _ = _load_in_chromium(root)
    assert report["broken"] == ["two/previews/normals.png"]
