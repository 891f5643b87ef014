"""spectrinsic.gt_export"""
