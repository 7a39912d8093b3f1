"""``python -m identification``: the command line of ``identification.cli``."""
import sys

from identification.cli import main

if __name__ == "__main__":
    sys.exit(main())
