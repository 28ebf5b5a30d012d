"""Helpers shared by the report tests: an HTML reader for the built pages, the self-containment
check, headless Chromium, and writing a case into a test catalogue."""

from __future__ import annotations

import base64
import re
import shutil
import subprocess
import tempfile
from html.parser import HTMLParser
from pathlib import Path

import fakes

PYTHON = "/usr/bin/python3"
CHROMIUM = shutil.which("chromium")


class Page(HTMLParser):
    """Collects <img> sources, ids, local links and the rows of the first summary table."""

    def __init__(self):
        super().__init__()
        self.imgs, self.ids, self.hrefs, self.links = [], set(), [], []
        self.rows: list[list[str]] = []
        self._in_summary = 0
        self._row: list[str] | None = None
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "img":
            self.imgs.append(a.get("src", ""))
        if tag == "a" and "href" in a:
            self.hrefs.append(a["href"])
        if tag == "link":
            self.links.append(a)
        if tag == "table" and "summary" in (a.get("class") or "") and not self.rows:
            self._in_summary = 1
        if self._in_summary and tag == "tr":
            self._row = []
        if self._in_summary and tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if self._in_summary and tag in ("td", "th") and self._cell is not None and self._row is not None:
            self._row.append(" ".join("".join(self._cell).split()))
            self._cell = None
        if self._in_summary and tag == "tr" and self._row is not None:
            self.rows.append(self._row)
            self._row = None
        if self._in_summary and tag == "table":
            self._in_summary = 0

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def parse(path: Path) -> Page:
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def summary(page: Page) -> dict[str, dict[str, str]]:
    header, *rows = page.rows
    return {r[0]: dict(zip(header, r)) for r in rows}


def chromium(*args: str) -> subprocess.CompletedProcess:
    profile = tempfile.mkdtemp(prefix="caplab-test-chromium-")
    try:
        return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                               "--disable-background-networking", "--disable-component-update", "--disable-sync",
                               "--no-first-run", f"--user-data-dir={profile}", *args],
                              capture_output=True, text=True, timeout=180)
    finally:
        shutil.rmtree(profile, ignore_errors=True)


def write_case(catalogue: Path, case: dict) -> Path:
    path = catalogue / (case["id"] + ".json")
    path.parent.mkdir(parents=True, exist_ok=True)
    fakes.write_json(path, case)
    return path


def assert_self_contained(out: Path) -> None:
    """No external stylesheet or script, every image an embedded PNG, every local link resolves."""
    for html in out.rglob("*.html"):
        page = parse(html)
        assert not page.links, f"{html}: external stylesheet"
        text = html.read_text(encoding="utf-8")
        assert not re.search(r"<script[^>]+src=", text)
        for src in page.imgs:
            assert src.startswith("data:image/png;base64,"), f"{html}: <img src={src[:60]}>"
            assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
        for href in page.hrefs:
            if href.startswith("#"):
                assert href[1:] in page.ids, f"{html}: dangling link {href}"
