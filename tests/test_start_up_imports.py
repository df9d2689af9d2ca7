"""What a command imports before it needs it (issue 37 item 4: start-up overhead). No time is
asserted: the modules a command must not load are checked in a fresh interpreter."""

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.processes

HEAVY = ("networkx", "trimesh", "matplotlib", "numba", "pandas", "sklearn")


def _loaded(code: str) -> list[str]:
    """The modules of :data:`HEAVY` loaded after ``code`` in a new interpreter."""
    report = f"import json, sys\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    probe = f"{code}\n{report}"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, timeout=120, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_simulate_help_loads_no_heavy_module():
    code = (
        "from holofold.cli import main\n"
        "try:\n    main(['simulate', '--help'])\nexcept SystemExit:\n    pass"
    )
    assert _loaded(code) == []


def test_a_crease_pattern_does_not_load_networkx():
    """networkx (0.2 s CPU) loads in ``CreasePattern.to_networkx`` only, not with every
    pattern (the scenarios and ``holofold simulate`` build patterns; was a module import)."""
    code = (
        "from holofold.geometry.miura import miura_sheet\n"
        "p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=1.0, ext=0.6)"
    )
    assert _loaded(code) == []
    assert "networkx" in _loaded(code + "\ng = p.to_networkx()")
