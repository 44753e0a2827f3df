"""Cutroom's benchmarks, outside the installed packages, run by one runner:
``python -m benchmarks NAME [--against REV]`` (``__main__``; the names are in
``registry``). What they share is in ``harness``; the benchmarks are grouped by subject:
``quality`` (how well and how fast the detector cuts), ``io`` (reading capture files),
``service`` (the service end to end) and ``library`` (the segment library's list and
search). Their figures live in ``results/``, one generated file per name."""
