"""``python -m fenics_contact.cli``: the same as the ``fenics-contact`` command."""

import sys

from fenics_contact.cli import main

sys.exit(main())
