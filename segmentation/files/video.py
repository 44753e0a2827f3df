"""Reference videos: what a file is, and whether a browser can play it.

Browsers play MP4 holding H.264 (8-bit 4:2:0) and WebM holding VP8, VP9 or AV1; a studio's
camera files are often something else (HEVC, ProRes in a QuickTime .mov, AVI), which a
``<video>`` element refuses with no reason given. So an upload is checked here first:

- its first bytes must be an MP4 (``ftyp`` box, not QuickTime's ``qt`` brand) or a WebM
  (EBML header whose doctype is ``webm``): ``container``;
- where ffprobe (Debian's ``ffmpeg`` package) is installed, it reads the streams: the
  video codec and pixel format must be ones browsers decode, and the duration, frame rate
  and size are kept. Without ffprobe those stay unknown (None) and only the container is
  checked.

``VideoRefused`` names the file and the reason.
"""

import dataclasses
import json
import shutil
import subprocess
from fractions import Fraction

from django.conf import settings

from motionlib.errors import shorten
from segmentation.errors import UploadError

CONTAINERS = {"mp4": "video/mp4", "webm": "video/webm"}
EXTENSIONS = {".mp4": "mp4", ".m4v": "mp4", ".webm": "webm"}
# Video codecs (ffprobe's names) a browser's <video> decodes, per container.
PLAYABLE = {"mp4": {"h264"}, "webm": {"vp8", "vp9", "av1"}}
# H.264 pixel formats browsers decode (10-bit and 4:2:2/4:4:4 profiles do not play).
H264_PIXEL_FORMATS = {"yuv420p", "yuvj420p"}
CODEC_NAMES = {"hevc": "HEVC (H.265)", "prores": "Apple ProRes", "mpeg4": "MPEG-4 Part 2",
               "mjpeg": "Motion JPEG", "dnxhd": "Avid DNxHD", "mpeg2video": "MPEG-2"}
PROBE_SECONDS = 30
HEADER_BYTES = 64


class VideoRefused(UploadError):
    """A file that is not a video a browser can play; the message names file and reason."""


@dataclasses.dataclass(frozen=True)
class VideoFacts:
    """What is known of a playable video. ``duration`` in seconds and ``fps`` in frames per
    second are None when ffprobe is not installed (``probed`` False) or did not say."""

    container: str
    codec: str = ""
    duration: float | None = None
    fps: float | None = None
    width: int | None = None
    height: int | None = None
    probed: bool = False

    @property
    def content_type(self):
        return CONTAINERS[self.container]


def ffprobe_path():
    """The ffprobe program to run (``CUTROOM_FFPROBE``, default ``ffprobe`` on PATH), or
    None when it is not installed."""
    return shutil.which(settings.CUTROOM_FFPROBE) if settings.CUTROOM_FFPROBE else None


def inspect(path, name):
    """The facts of the video file at ``path`` (uploaded as ``name``); VideoRefused says
    why a browser could not play it."""
    container = sniff_container(path, name)
    program = ffprobe_path()
    if program is None:
        return VideoFacts(container=container)
    return _probe(program, path, name, container)


def sniff_container(path, name):
    """``mp4`` or ``webm`` from the file's first bytes (the extension is not trusted)."""
    with open(path, "rb") as handle:
        head = handle.read(HEADER_BYTES)
    shown = shorten(name)
    if head[4:8] == b"ftyp":
        if head[8:12] == b"qt  ":
            raise VideoRefused(f"file: {shown} is a QuickTime .mov (often ProRes), which "
                               "browsers do not play; export it as MP4 (H.264) or WebM")
        return "mp4"
    if head.startswith(b"\x1a\x45\xdf\xa3"):
        if b"webm" in head:
            return "webm"
        raise VideoRefused(f"file: {shown} is a Matroska (.mkv) file, which browsers do not "
                           "play; remux or export it as WebM (VP9) or MP4 (H.264)")
    if head.startswith(b"RIFF") and head[8:12] == b"AVI ":
        raise VideoRefused(f"file: {shown} is an AVI file, which browsers do not play; "
                           "export it as MP4 (H.264) or WebM (VP9)")
    raise VideoRefused(f"file: {shown} is not a video browsers play (its first bytes are "
                       "neither MP4 nor WebM); upload an MP4 (H.264) or a WebM (VP8/VP9/AV1)")


def _probe(program, path, name, container):
    shown = shorten(name)
    command = [program, "-v", "error", "-of", "json", "-show_entries",
               "format=format_name,duration:stream=codec_type,codec_name,pix_fmt,"
               "avg_frame_rate,r_frame_rate,width,height,duration", path]
    try:
        done = subprocess.run(command, capture_output=True, timeout=PROBE_SECONDS, check=False)
        info = json.loads(done.stdout or b"{}")
    except subprocess.TimeoutExpired:
        raise VideoRefused(f"file: {shown} could not be read by ffprobe within "
                           f"{PROBE_SECONDS} s") from None
    except ValueError:
        info = {}
    if done.returncode != 0 or "format" not in info:
        lines = done.stderr.decode(errors="replace").strip().splitlines()
        reason = shorten(lines[-1].replace(str(path), name) if lines else "no streams found", 120)
        raise VideoRefused(f"file: {shown} is not a readable video (ffprobe: {reason})")
    streams = [s for s in info.get("streams", []) if s.get("codec_type") == "video"]
    if not streams:
        raise VideoRefused(f"file: {shown} has no video stream")
    stream = streams[0]
    _check_codec(shown, container, stream)
    return VideoFacts(
        container=container, codec=stream.get("codec_name", ""),
        duration=_number(stream.get("duration")) or _number(info["format"].get("duration")),
        fps=_rate(stream.get("avg_frame_rate")) or _rate(stream.get("r_frame_rate")),
        width=stream.get("width"), height=stream.get("height"), probed=True,
    )


def _check_codec(shown, container, stream):
    codec = stream.get("codec_name", "unknown")
    if codec not in PLAYABLE[container]:
        named = CODEC_NAMES.get(codec, codec)
        wanted = "H.264" if container == "mp4" else "VP8, VP9 or AV1"
        raise VideoRefused(f"file: {shown} is {named} video in {container.upper()}, which "
                           f"browsers do not play; {container.upper()} must hold {wanted} "
                           "(e.g. `ffmpeg -i in -c:v libx264 -pix_fmt yuv420p out.mp4`)")
    pixels = stream.get("pix_fmt")
    if codec == "h264" and pixels and pixels not in H264_PIXEL_FORMATS:
        raise VideoRefused(f"file: {shown} is H.264 with pixel format {pixels} (10-bit or "
                           "4:2:2/4:4:4), which browsers do not play; re-encode with "
                           "-pix_fmt yuv420p")


def _number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if value > 0 else None


def _rate(text):
    try:
        value = float(Fraction(text))
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return round(value, 6) if value > 0 else None
