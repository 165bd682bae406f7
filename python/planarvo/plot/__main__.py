"""python3 -m planarvo.plot: see _cli.py."""
import sys

try:
    import matplotlib  # noqa: F401
    import numpy  # noqa: F401
except ImportError as e:
    print("planarvo plot: %s: the figures need matplotlib and numpy; install python3-matplotlib "
          "(scripts/install-deps.sh installs it)" % e, file=sys.stderr)
    sys.exit(2)

from ._cli import main  # noqa: E402

sys.exit(main())
