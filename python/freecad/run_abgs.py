"""Entry point for ``freecadcmd``: STEP in, .FCStd out.

    freecadcmd -P SITE python/freecad/run_abgs.py part.step part.FCStd
    ABGS_ARGS="--relative-length 0.02 --quiet" freecadcmd -P SITE python/freecad/run_abgs.py ...

``SITE`` is the site-packages folder holding the abgs and gmsh packages for
FreeCAD's Python (``-P`` or ``$ABGS_SITE``, see ``abgs_freecad.add_site``);
options go in ``$ABGS_ARGS`` because freecadcmd takes every ``-option`` for
itself (``ABGS_ARGS=--help`` lists them). Exits with the status of
``abgs_freecad.main`` (non-zero on failure, with the traceback).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import abgs_freecad  # noqa: E402  (after the path is set)

abgs_freecad.add_site()
# freecadcmd leaves the values of its own options (e.g. -P's folder) in
# sys.argv before the script's name: the script's arguments follow its name.
me = os.path.basename(__file__)
start = next((i + 1 for i, a in enumerate(sys.argv) if os.path.basename(a) == me), 1)
try:
    status = abgs_freecad.main_from_freecadcmd(sys.argv[start:])
except SystemExit:
    raise
except BaseException:
    # freecadcmd reports an exception but exits 0: make the failure visible.
    import traceback

    traceback.print_exc()
    status = 1
raise SystemExit(status)
