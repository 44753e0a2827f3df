"""The compiled parts of motionlib (everything else about the package is in pyproject.toml):
its number reader, its forward kinematics and its DTW, C with only the buffer protocol, so building
needs a C compiler and Python's headers and nothing else."""

from setuptools import Extension, setup

setup(ext_modules=[
    Extension("motionlib.io._parse", ["motionlib/io/_parse.c"]),
    # No fused multiply-adds (compilers contract a * b + c into one where the CPU has it):
    # body_frame() must round as numpy's separate multiplies and adds do.
    Extension("motionlib._kinematics", ["motionlib/_kinematics.c"],
              extra_compile_args=["-ffp-contract=off"]),
    Extension("motionlib._dtw", ["motionlib/_dtw.c"]),
])
