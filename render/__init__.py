"""spectrinsic.render"""
