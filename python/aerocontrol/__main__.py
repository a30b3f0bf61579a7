"""``python -m aerocontrol``: the same as the ``aerocontrol`` command."""

from .cli import main

raise SystemExit(main())
