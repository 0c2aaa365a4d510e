"""Error metrics and statistical image comparisons for tests and benchmarks: one name for the
two layers, block statistics (lantern/blocks.py) and the comparison of renders every render
test uses, compare_renders / assert_agreement with its negative controls (lantern/agreement.py,
tests/README.md). Neither layer imports this module, so nothing here is circular."""

from .agreement import (DEFAULT_BIAS_CAP, Agreement, assert_agreement,  # noqa: F401
                        compare_renders, negative_controls, paired_sets)
from .blocks import (Comparison, SeedBlocks, _as3, _exact_blocks, _mask3, _z,  # noqa: F401
                     agreement, binomial_bound, block_means, block_stats, compare_sets,
                     compare_to_reference, mean_relative_difference, relative_rmse, rmse,
                     seed_blocks, t_tail, z_threshold)
