"""``python -m fleet.cli``: how the launcher starts AGV hosts and the recorder."""

import sys

from fleet.cli.main import main

sys.exit(main())
