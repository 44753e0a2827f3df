"""Real video files for the tests, made by Debian's ffmpeg: a test pattern with its frame
number burnt in, in the containers and codecs a studio's cameras and editors produce.

Each file is made once per test process for each set of arguments.
"""

import functools
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

FFMPEG = shutil.which("ffmpeg")
FOLDER = Path(tempfile.mkdtemp(prefix="cutroom-test-videos-"))

# Encoder options per kind: (file extension, ffmpeg output options).
KINDS = {
    "h264": (".mp4", ["-c:v", "libx264", "-pix_fmt", "yuv420p", "-preset", "ultrafast",
                      "-g", "15", "-movflags", "+faststart"]),
    "vp9": (".webm", ["-c:v", "libvpx-vp9", "-b:v", "200k", "-deadline", "realtime",
                      "-cpu-used", "8"]),
    "hevc": (".mp4", ["-c:v", "libx265", "-x265-params", "log-level=error", "-tag:v", "hvc1"]),
    "prores": (".mov", ["-c:v", "prores_ks", "-profile:v", "0"]),
    "avi": (".avi", ["-c:v", "mpeg4"]),
    "h264-10bit": (".mp4", ["-c:v", "libx264", "-pix_fmt", "yuv420p10le", "-preset", "ultrafast"]),
}


def needs_ffmpeg():
    if FFMPEG is None:
        pytest.skip("ffmpeg is not installed (make browser installs Debian's package)")


@functools.cache
def make_video(kind="h264", seconds=2.0, fps=30, size="160x120"):
    """The path of a video of ``seconds`` at ``fps`` whose every frame shows its number."""
    needs_ffmpeg()
    extension, options = KINDS[kind]
    path = FOLDER / f"{kind}-{seconds:g}s-{fps}fps-{size}{extension}"
    pattern = (f"testsrc=duration={seconds}:size={size}:rate={fps},"
               "drawtext=text='%{frame_num}':x=4:y=4:fontsize=28:fontcolor=white:box=1:"
               "boxcolor=black")
    done = subprocess.run([FFMPEG, "-v", "error", "-y", "-f", "lavfi", "-i", pattern,
                           *options, str(path)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return path
