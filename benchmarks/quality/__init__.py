"""The segmentation research apparatus, outside the installed library: the quality
benchmark (``bench``, its ``tables``, ``checks`` and ``unmatched`` checks), the labelled
takes it scores (``data``, ``variants``), the choice of the default detector's settings
(``tuning``) and motionlib's speed tables (``speed``).

``python -m benchmarks.quality [--loo]`` and ``python -m benchmarks.quality speed io|adapt``
(``cli``); ``make bench`` writes their output to ``benchmarks/results/``. A new experiment
is an option or subclass registered here, never a parameter shipped in ``motionlib``.
"""
