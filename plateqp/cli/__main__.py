"""``python -m plateqp.cli``: the ``plateqp`` command."""

import sys

from . import main

sys.exit(main())
