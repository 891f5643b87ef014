"""The render's pure algebra: modes and channel values, light shares and sums, the per-light transport and its composition (numpy only, no Mitsuba)."""
