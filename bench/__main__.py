"""``python -m spectrinsic.bench``: see :func:`spectrinsic.bench.main`."""

import sys

from spectrinsic.bench import main

sys.exit(main())
