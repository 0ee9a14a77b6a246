"""Package list for setuptools.

shaders/, graphs/ and ui/ live at the top of the checkout and ship inside the
wheel as matedit/shaders, matedit/graphs and matedit/ui; matedit/resources.py
finds them in either place.
"""

from pathlib import Path

from setuptools import find_packages, setup

ROOT = Path(__file__).parent
DATA_DIRS = ("shaders", "graphs", "ui")


def _data_packages() -> dict[str, str]:
    mapping = {}
    for top in DATA_DIRS:
        for d in [ROOT / top, *sorted(p for p in (ROOT / top).rglob("*") if p.is_dir())]:
            rel = d.relative_to(ROOT)
            name = "matedit." + ".".join(rel.parts)
            mapping[name] = rel.as_posix()
    return mapping


DATA = _data_packages()
setup(
    packages=find_packages(include=["matedit", "matedit.*"]) + sorted(DATA),
    package_dir=DATA,
)
