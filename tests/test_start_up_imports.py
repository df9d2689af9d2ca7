"""What a command imports before it needs it (issue 37 item 4: start-up overhead). No time is
asserted: the modules a command must not load are checked in a fresh interpreter."""

import json
import subprocess
import sys
from pathlib import Path

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


#: modules ``holofold simulate`` writes its usual files without (issue 37 item 4: trimesh and
#: networkx were the STL/OBJ writer's, matplotlib with pyplot and mplot3d the picture's,
#: scipy.spatial the line reader's point merging and the printability's panel pairs)
NOT_IN_SIMULATE = ("trimesh", "networkx", "matplotlib", "matplotlib.pyplot", "mpl_toolkits",
                   "scipy.spatial")  # fmt: skip


@pytest.mark.parametrize("contact", ["--contact", "--no-contact"])
def test_simulate_writes_its_files_without_trimesh_or_pyplot(tmp_path, contact):
    """A whole ``holofold simulate`` run (SVG in; FOLD, STL, OBJ, CSV, JSON and PNG out) loads
    none of :data:`NOT_IN_SIMULATE` (a lazy placeholder in ``sys.modules`` is not a load)."""
    if contact == "--contact":
        pytest.importorskip("ipctk")
    svg = Path(__file__).parent / "data" / "origami-simulator" / "waterbombBase.svg"
    out = tmp_path / "out"
    argv = ["simulate", str(svg), contact, "--fold", "0.3", "-o", str(out)]
    code = (
        "import importlib.util, json, sys\n"
        "from holofold.cli import main\n"
        f"code = main({argv!r})\n"
        "lazy = importlib.util._LazyModule\n"
        f"print(json.dumps([code, [m for m in {NOT_IN_SIMULATE!r} if m in sys.modules\n"
        "                          and not isinstance(sys.modules[m], lazy)]]))"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    status, loaded = json.loads(run.stdout.strip().splitlines()[-1])
    assert status in (0, 1), run.stderr[-2000:]
    names = sorted(p.name for p in out.iterdir())
    assert names == ["folded.fold", "folded.obj", "folded.stl", "panels.csv", "picture.png",
                     "simulation.json"]  # fmt: skip
    assert loaded == []
