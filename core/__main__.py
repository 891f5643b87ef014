import sys

from spectrinsic.cli import main

sys.exit(main())
