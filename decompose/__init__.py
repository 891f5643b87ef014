"""spectrinsic.decompose"""
