"""What the tests of ``benchmarks/*.py`` share: those scripts are files, not a package, so
a test loads one by path, with its folder importable as it is for a script run as a file
(the scripts import their siblings, e.g. ``busy.py``; the research probes of
``studies/probes/`` import ``probe.py`` and are loaded the same way)."""

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def load_script(name: str, folder: Path = BENCHMARKS) -> ModuleType:
    """``<folder>/<name>.py`` (``benchmarks/`` by default) imported as the module ``name``."""
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    spec = importlib.util.spec_from_file_location(name, folder / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
