"""Cutroom's benchmarks: the service's (scripts beside this file, run as
``python benchmarks/<name>.py``) and the segmentation research apparatus
(``python -m benchmarks.quality``). Not part of the installed packages."""
