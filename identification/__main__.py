"""``python -m identification``: the command line of ``identification.cli.arguments``."""
import sys

from identification.cli.arguments import main

if __name__ == "__main__":
    sys.exit(main())
