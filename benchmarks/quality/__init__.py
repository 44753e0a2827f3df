"""The segmentation research apparatus, outside the installed library: the quality
benchmark (``bench``, its ``tables``, ``checks`` and ``unmatched`` checks), the labelled
takes it scores (``data``, ``variants``), the choice of the default detector's settings
(``tuning``), motionlib's speed tables (``speed``), the learning curve (``learning``)
and segmentation quality on point takes (``points``).

``python -m benchmarks quality|learning-curve|speed-io|speed-adapt`` run ``cli`` with the
registered arguments (``benchmarks/registry.py``) and record their output to
``benchmarks/results/``. A new experiment
is an option or subclass registered here, never a parameter shipped in ``motionlib``.
"""
