"""``python -m plateqp.cli``: the ``plateqp`` command."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
