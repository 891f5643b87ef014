"""The band path: one traversal for every band of every diagonal mode, split by light (kernel, integrator, traversal)."""
