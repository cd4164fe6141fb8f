"""Run the walk-through's commands in a fresh environment; paste what they print.

    python docs/tools/gen_walkthrough.py /path/to/fresh-venv/bin

Each ``@@command@@`` of ``walkthrough.md.in`` (several lines allowed) runs in bash, in one
scratch folder shared by all of them, with the given ``bin`` folder first on ``PATH`` and
``$DATA`` pointing at the records shipped with clpc; the command and its output (standard
error included, and the exit code when it is not 0) replace the marker in
``docs/walkthrough.md``.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

BIN = Path(sys.argv[1]).resolve()
PY = BIN / "python"
DATA = subprocess.run(
    [str(PY), "-c", "import clpc.datasets as d, os; print(os.path.dirname(d.path('dryer')))"],
    capture_output=True,
    text=True,
    check=True,
).stdout.strip()
WORK = Path(tempfile.mkdtemp(prefix="clpc-walkthrough-"))
ENV = dict(os.environ, DATA=DATA, PATH=f"{BIN}:{os.environ['PATH']}", COLUMNS="100")
ENV.pop("CLPC_FAST_IO", None)


def sh(cmd: str) -> str:
    """One command as a terminal shows it: the prompt, the command, its output."""
    p = subprocess.run(
        ["bash", "-c", "{ " + cmd + "\n} 2>&1"], cwd=WORK, env=ENV, capture_output=True, text=True
    )
    out = p.stdout.rstrip("\n").replace(DATA, "$DATA").replace(str(WORK), ".")
    code = f"\n[exit code {p.returncode}]" if p.returncode else ""
    shown = cmd.strip("\n")
    return f"$ {shown}\n{out}{code}" if out else f"$ {shown}{code}"


template = (Path(__file__).parent / "walkthrough.md.in").read_text()
doc = re.sub(r"@@(.+?)@@", lambda m: sh(m.group(1)), template, flags=re.S)
(Path(__file__).parents[1] / "walkthrough.md").write_text(doc)
print(doc)
