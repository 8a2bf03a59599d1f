"""Every dependency of pyproject.toml (its extras included) declares a lower bound, and
.ci/constraints-oldest.txt pins each at exactly that bound: the "oldest" set of .ci/run is then
what pyproject.toml allows at its oldest. Exit 1, naming each mismatch, otherwise."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Extras the oldest set does not install (the documentation is built in the newest set only).
UNPINNED_EXTRAS = ("docs",)
REQ = re.compile(r"^([A-Za-z0-9_.-]+)(\[[^\]]*\])?\s*(.*)$")


def norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def main() -> int:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    reqs = list(project["dependencies"])
    for extra, group in project["optional-dependencies"].items():
        if extra in UNPINNED_EXTRAS:
            continue
        reqs += [r for r in group if not r.startswith(project["name"] + "[")]
    pins = {}
    for line in (ROOT / ".ci" / "constraints-oldest.txt").read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, _, version = line.partition("==")
            pins[norm(name)] = version.strip()
    bad = []
    for r in reqs:
        name, _, spec = REQ.match(r).groups()
        bound = re.search(r">=\s*([^,;\s]+)", spec)
        if bound is None:
            bad.append(f"{name}: no lower bound in pyproject.toml")
        elif pins.get(norm(name)) != bound.group(1):
            bad.append(f"{name}: pyproject.toml says >={bound.group(1)}, the constraints pin "
                       f"{pins.get(norm(name), 'nothing')}")
    for line in bad:
        print(f"check_bounds: {line}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
