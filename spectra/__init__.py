"""spectrinsic.spectra"""
