"""``python -m spectrinsic.bench``: see :func:`spectrinsic.bench.main`."""

import sys

from . import main

sys.exit(main())
