"""Headless Debian chromium for the tests that look at a page as a browser does."""

from __future__ import annotations

import shutil
import subprocess

import pytest


def chromium(tmp_path, *args):
    """Run chromium headless with ``args`` (e.g. ``--dump-dom URL``); fails on a JS error."""
    exe = shutil.which("chromium")
    if exe is None:
        pytest.skip("chromium not installed: apt-get install chromium")
    profile = tmp_path / f"profile-{len(list(tmp_path.glob('profile-*')))}"
    flags = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={profile}",
        "--enable-logging=stderr",  # console messages (JS errors) go to stderr
        "--v=0",
    ]
    done = subprocess.run(
        [exe, *flags, *args], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Uncaught" not in done.stderr, done.stderr[-2000:]
    return done
