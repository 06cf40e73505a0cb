"""``python -m oceangnc ...``: the command line (same as the ``oceangnc`` script)."""

import sys

from .cli import main

sys.exit(main())
