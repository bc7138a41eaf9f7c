"""``python -m rockyade.cli``: the same as the ``rockyade`` command."""

import sys

from rockyade.cli import main

sys.exit(main())
