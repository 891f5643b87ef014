"""The decomposers: the thesis' names-and-shades, colour Retinex, baselines, their parts and registry."""
