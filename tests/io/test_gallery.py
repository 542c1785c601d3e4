"""`hybridgen gallery`: the static page renders in headless Chromium (Debian's `chromium`, installed by
tools/install_system_deps.sh --test): every image loads at its real width, legends name the ids and give the
depth scale, paths are relative, and the scene filter works."""
from __future__ import annotations

import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.data import KeypointDataset
from tests.data.scenes import config_text

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")


def chromium(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.fail("headless Chromium is missing: run `sudo bash tools/install_system_deps.sh --test` "
                    "(Debian package chromium)")
    profile = tmp_path / "chromium-profile"
    profile.mkdir(exist_ok=True)
    return subprocess.run([exe, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args], capture_output=True,
                          text=True, timeout=120)


class _Elements(HTMLParser):
    """Every element's tag and attributes, plus the text of legend tables."""

    def __init__(self) -> None:
        super().__init__()
        self.elements: list[tuple[str, dict[str, str]]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.elements.append((tag, {k: v or "" for k, v in attrs}))

    def handle_data(self, data):
        self.text.append(data)


@pytest.fixture(scope="module")
def gallery(tmp_path_factory, gl_context):
    tmp = tmp_path_factory.mktemp("gallery")
    config = tmp / "config.yaml"
    config.write_text(config_text(scenes=2, chunk=2))
    hg.run_config(config, [str(tmp / "out")])
    return tmp / "out"


def test_page_loads_every_image_with_legends(gallery, tmp_path, run_cli):
    code, out, err = run_cli("gallery", str(gallery))
    assert code == 0, err
    page = gallery / "gallery/index.html"
    assert str(page) in out
    text = page.read_text()
    sources = re.findall(r'(?:src|href)="([^"]+)"', text)
    assert sources and all(not s.startswith(("/", "http:", "https:", "file:")) for s in sources)  # relative only
    done = chromium(tmp_path, "--virtual-time-budget=10000", "--dump-dom", page.as_uri())
    assert done.returncode == 0, done.stderr[-2000:]
    dom = _Elements()
    dom.feed(done.stdout)
    check = next(attrs for tag, attrs in dom.elements if attrs.get("id") == "image-check")
    images = [attrs for tag, attrs in dom.elements if tag == "img" and "data-full" in attrs]
    data = KeypointDataset(gallery)
    passes = {"colors", "depth", "distance", "normals", "instance_segmaps", "category_id_segmaps", "part_segmaps",
              "albedo", "nocs", "forward_flow", "backward_flow", "forward_flow_occluded", "backward_flow_occluded"}
    assert {attrs["src"].split("_", 1)[1][:-4] for attrs in images} == passes
    assert len(images) == len(data) * len(passes)
    assert int(check["data-failed"]) == 0 and int(check["data-loaded"]) == int(check["data-total"]) > len(images)
    assert check["data-lightbox"] == "none"  # the enlarged view stays closed until a click
    for attrs in images:  # the browser decoded each thumbnail at the width of the file on disk
        with Image.open(page.parent / attrs["src"]) as thumb:
            assert int(attrs["data-natural-width"]) == thumb.width == 40  # 40x30 images are not downscaled
        assert (page.parent / attrs["data-full"]).is_file()
    # legends: instance ids named with their category, depth scale in metres of the keypoint's range
    words = " ".join(dom.text)
    assert "box (category 2)" in words and "ball (category 3)" in words and "background" in words
    depth = data[0]["depth"]
    finite = depth[np.isfinite(depth)]
    first = text.split('id="kp1"')[0]
    assert f"{finite.min():.3f} m" in first and f"{finite.max():.3f} m" in first
    assert sum(1 for tag, attrs in dom.elements if attrs.get("class") == "legend ids") >= 3 * len(data)


def test_scene_filter_and_screenshot(gallery, tmp_path):
    from hybridgen.io.gallery import build_gallery

    build_gallery(gallery, tmp_path / "g")
    page = build_gallery(gallery, tmp_path / "g", keys=["colors", "depth", "instance_segmaps"])
    kept = sorted(p.name for p in (tmp_path / "g/thumbs").iterdir())  # the first gallery's other passes are gone
    assert kept == sorted(f"{i:06d}_{k}.png" for i in range(6) for k in ("colors", "depth", "instance_segmaps"))
    done = chromium(tmp_path, "--virtual-time-budget=10000", "--dump-dom", page.as_uri() + "#scene=1")
    assert done.returncode == 0, done.stderr[-2000:]
    dom = _Elements()
    dom.feed(done.stdout)
    sections = [attrs for tag, attrs in dom.elements if tag == "section"]
    assert len(sections) == 6
    for attrs in sections:
        assert ("hidden" in attrs["class"]) == (attrs["data-scene"] != "1")
    # the enlarged view, as a click opens it (the page's #open= runs the click handler's function)
    done = chromium(tmp_path, "--virtual-time-budget=10000", "--dump-dom", page.as_uri() + "#open=000004_depth")
    dom = _Elements()
    dom.feed(done.stdout)
    check = next(attrs for tag, attrs in dom.elements if attrs.get("id") == "image-check")
    assert check["data-lightbox"] == "flex" and check["data-lightbox-width"] == "40"
    enlarged = next(attrs for tag, attrs in dom.elements if tag == "img" and attrs.get("alt") == "enlarged pass")
    assert enlarged["src"] == "images/000004_depth.png"
    shot = tmp_path / "shot.png"
    done = chromium(tmp_path, "--window-size=900,700", f"--screenshot={shot}", "--virtual-time-budget=10000",
                    page.as_uri())
    assert done.returncode == 0 and shot.is_file(), done.stderr[-2000:]
    pixels = np.asarray(Image.open(shot).convert("RGB"))
    assert pixels.shape[:2] == (700, 900) and len(np.unique(pixels.reshape(-1, 3), axis=0)) > 50
