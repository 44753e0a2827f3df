"""Cutroom settings, read from environment variables only.

With nothing set, Cutroom runs embedded: SQLite and a SQLite-file Celery broker under
``var/``, originals under ``var/media/``. Production sets ``DATABASE_URL`` (PostgreSQL)
and ``CELERY_BROKER_URL`` (Redis). ``.env.example`` lists every variable.
"""

import os
from pathlib import Path

import dj_database_url


def envbool(name, default):
    value = os.environ.get(name)
    if value is None or value == "":
        return default
    if value.lower() in ("1", "true", "yes", "on"):
        return True
    if value.lower() in ("0", "false", "no", "off"):
        return False
    raise ValueError(f"{name} must be true or false, got {value!r}")


def envint(name, default):
    value = os.environ.get(name)
    if value is None or value == "":
        return default
    try:
        return int(value)
    except ValueError:
        raise ValueError(f"{name} must be an integer, got {value!r}") from None


def envlist(name, default):
    value = os.environ.get(name)
    if value is None or value == "":
        return default
    return [item.strip() for item in value.split(",") if item.strip()]


BASE_DIR = Path(__file__).resolve().parent.parent
VAR_DIR = Path(os.environ.get("CUTROOM_VAR_DIR") or BASE_DIR / "var")
FRONTEND_DIST = Path(os.environ.get("CUTROOM_FRONTEND_DIST") or BASE_DIR / "frontend" / "dist")

DEBUG = envbool("DEBUG", False)
# The embedded default must start without configuration; production sets its own key.
SECRET_KEY = os.environ.get("SECRET_KEY") or "cutroom-embedded-insecure-key-set-SECRET_KEY"
ALLOWED_HOSTS = envlist("ALLOWED_HOSTS", ["127.0.0.1", "localhost", "testserver"])
CSRF_TRUSTED_ORIGINS = envlist("CSRF_TRUSTED_ORIGINS", [])
SITE_NAME = os.environ.get("SITE_NAME", "Cutroom")

INSTALLED_APPS = [
    "django.contrib.admin",
    "django.contrib.auth",
    "django.contrib.contenttypes",
    "django.contrib.sessions",
    "django.contrib.messages",
    "whitenoise.runserver_nostatic",
    "django.contrib.staticfiles",
    "rest_framework",
    "drf_spectacular",
    "drf_spectacular_sidecar",  # Swagger UI served from /static/, not a CDN
    "accounts",
    "segmentation",
]

MIDDLEWARE = [
    "django.middleware.security.SecurityMiddleware",
    "cutroom.security.ContentSecurityPolicyMiddleware",
    "whitenoise.middleware.WhiteNoiseMiddleware",
    "cutroom.lanes.LaneMiddleware",
    "django.contrib.sessions.middleware.SessionMiddleware",
    "django.middleware.common.CommonMiddleware",
    "django.middleware.csrf.CsrfViewMiddleware",
    "django.contrib.auth.middleware.AuthenticationMiddleware",
    "accounts.middleware.new_password_first",
    "segmentation.api.common.pathids.PathIdMiddleware",
    "django.contrib.messages.middleware.MessageMiddleware",
    "django.middleware.clickjacking.XFrameOptionsMiddleware",
]

ROOT_URLCONF = "cutroom.urls"
WSGI_APPLICATION = "cutroom.wsgi.application"

TEMPLATES = [
    {
        "BACKEND": "django.template.backends.django.DjangoTemplates",
        "DIRS": [],
        "APP_DIRS": True,
        "OPTIONS": {
            "context_processors": [
                "django.template.context_processors.request",
                "django.contrib.auth.context_processors.auth",
                "django.contrib.messages.context_processors.messages",
            ],
        },
    },
]

DATABASES = {
    "default": dj_database_url.parse(
        os.environ.get("DATABASE_URL") or f"sqlite:///{VAR_DIR / 'cutroom.sqlite3'}",
        conn_max_age=envint("DB_CONN_MAX_AGE", 0),
    )
}
if DATABASES["default"]["ENGINE"] == "django.db.backends.sqlite3":
    # The web server and the worker share the file: readers never block the writer
    # (WAL), writers take the lock up front and wait for it instead of failing.
    DATABASES["default"].setdefault("OPTIONS", {}).update(
        timeout=20,
        transaction_mode="IMMEDIATE",
        init_command="PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;",
    )
    if DATABASES["default"]["NAME"] not in ("", ":memory:"):
        # A fresh clone has no var/ yet; SQLite will not create the folder itself.
        Path(DATABASES["default"]["NAME"]).parent.mkdir(parents=True, exist_ok=True)

DEFAULT_AUTO_FIELD = "django.db.models.BigAutoField"

AUTH_PASSWORD_VALIDATORS = [
    {"NAME": "django.contrib.auth.password_validation.UserAttributeSimilarityValidator"},
    {"NAME": "django.contrib.auth.password_validation.MinimumLengthValidator"},
    {"NAME": "django.contrib.auth.password_validation.CommonPasswordValidator"},
    {"NAME": "django.contrib.auth.password_validation.NumericPasswordValidator"},
]
# Sign-in finds the account by any spelling of its username (accounts.usernames).
AUTHENTICATION_BACKENDS = [
    "accounts.backends.UsernameBackend",
    # The same backend's path before the accounts app left the project package, which
    # sessions made then still name (it only finds their user).
    "cutroom.accounts.backends.UsernameBackend",
]
# Behind a TLS-terminating proxy: trust its X-Forwarded-Proto and send cookies over HTTPS only.
if envbool("BEHIND_TLS_PROXY", False):
    SECURE_PROXY_SSL_HEADER = ("HTTP_X_FORWARDED_PROTO", "https")
SESSION_COOKIE_SECURE = CSRF_COOKIE_SECURE = envbool("SECURE_COOKIES", False)

# Sign-in throttling (/login/, /admin/login/, /api/auth/token/): within a sliding window
# of CUTROOM_LOGIN_WINDOW seconds, a username with this many failed sign-ins, or an
# address with that many, is refused (429, Retry-After) until the oldest leaves the window.
CUTROOM_LOGIN_WINDOW = envint("CUTROOM_LOGIN_WINDOW", 15 * 60)
CUTROOM_LOGIN_FAILURES_PER_USER = envint("CUTROOM_LOGIN_FAILURES_PER_USER", 10)
CUTROOM_LOGIN_FAILURES_PER_ADDRESS = envint("CUTROOM_LOGIN_FAILURES_PER_ADDRESS", 30)
# How many reverse proxies append to X-Forwarded-For in front of the web server (0: the
# client address is REMOTE_ADDR; a header clients can forge is never trusted by default).
CUTROOM_TRUSTED_PROXIES = envint("CUTROOM_TRUSTED_PROXIES", 0)
# An API token works for this many days after it was issued.
CUTROOM_TOKEN_DAYS = envint("CUTROOM_TOKEN_DAYS", 30)
# An invitation to join a project can be accepted for this many days.
CUTROOM_INVITATION_DAYS = envint("CUTROOM_INVITATION_DAYS", 14)
# Invitations one person may send per hour, and one username may receive per day from
# everyone (0 = no limit); past either, 429.
CUTROOM_INVITATIONS_PER_HOUR = envint("CUTROOM_INVITATIONS_PER_HOUR", 20)
CUTROOM_INVITATIONS_PER_INVITEE = envint("CUTROOM_INVITATIONS_PER_INVITEE", 5)

# Scripts only from our own files; inline styles are allowed (label colours are style
# attributes; so are parts of the admin and of Swagger UI), inline scripts are not.
CONTENT_SECURITY_POLICY = os.environ.get("CONTENT_SECURITY_POLICY") or "; ".join([
    "default-src 'self'",
    "script-src 'self'",
    "style-src 'self' 'unsafe-inline'",
    "img-src 'self' data: blob:",
    "font-src 'self' data:",
    "connect-src 'self'",
    "worker-src 'self' blob:",
    "object-src 'none'",
    "base-uri 'self'",
    "form-action 'self'",
    "frame-ancestors 'none'",
])

LOGIN_URL = "/login/"
LOGIN_REDIRECT_URL = "/"
LOGOUT_REDIRECT_URL = "/login/"

LANGUAGE_CODE = "en-us"
TIME_ZONE = "UTC"
USE_I18N = False
USE_TZ = True

# Static files: the built front end (frontend/dist) and the admin/DRF assets, at /static/.
STATIC_URL = "/static/"
# Only needed for `collectstatic`; WhiteNoise serves straight from the finders below.
STATIC_ROOT = os.environ.get("CUTROOM_STATIC_ROOT") or None
STATICFILES_DIRS = [FRONTEND_DIST]
# Serve straight from the finders so a fresh `npm run build` needs no collectstatic.
WHITENOISE_USE_FINDERS = True
WHITENOISE_AUTOREFRESH = DEBUG
# frontend/dist does not exist until the front end is built; the index view says so.
SILENCED_SYSTEM_CHECKS = ["staticfiles.W004"]
if DATABASES["default"]["ENGINE"] == "django.db.backends.sqlite3":
    # models.W040: SQLite has no INCLUDE columns, so there the library list's covering
    # indexes (LibrarySegment.Meta) are plain ones, and migrations 0020 and 0021 give SQLite
    # covering indexes of its own for the list (filtered columns trailing the keys).
    # Expected on every start of the embedded default, so not news.
    SILENCED_SYSTEM_CHECKS.append("models.W040")

MEDIA_URL = "/media/"
MEDIA_ROOT = Path(os.environ.get("CUTROOM_MEDIA_ROOT") or VAR_DIR / "media")
# The similar-clip vector indexes (segmentation.similar.index); rebuilt from the database.
SIMILAR_INDEX_DIR = Path(os.environ.get("CUTROOM_SIMILAR_INDEX_DIR") or VAR_DIR / "similar")
# Each web process reads an index's base (its profiles, 420 bytes a segment) into memory:
# searching the shared memory-mapped file costs twice the time (docs/operations.md).
SIMILAR_INDEX_IN_MEMORY = envbool("CUTROOM_SIMILAR_INDEX_IN_MEMORY", True)
STORAGES = {
    "default": {
        "BACKEND": os.environ.get(
            "CUTROOM_STORAGE_BACKEND", "django.core.files.storage.FileSystemStorage"
        ),
    },
    "staticfiles": {"BACKEND": "django.contrib.staticfiles.storage.StaticFilesStorage"},
}

# Sized for real takes: a studio's hour at 120 fps is a ~285 MB BVH, and the reader's
# frame limits (CUTROOM_MAX_FRAME_VALUES) refuse at ingest what a bigger file would hold
# (docs/operations.md, "Limits and quotas").
CUTROOM_MAX_UPLOAD_MB = envint("CUTROOM_MAX_UPLOAD_MB", 1024)
# Reference videos beside a take (segmentation.files.video): the size of one, and the
# ffprobe program that reads their codec, duration and frame rate (empty: do not probe;
# only the container is checked then, from the file's first bytes).
CUTROOM_MAX_VIDEO_MB = envint("CUTROOM_MAX_VIDEO_MB", 2048)
CUTROOM_FFPROBE = os.environ.get("CUTROOM_FFPROBE", "ffprobe")
# The form fields besides the files (Django refuses more with a generic 400). Uploaded files
# above FILE_UPLOAD_MAX_MEMORY_SIZE are streamed to a temporary file as they arrive, never
# held in memory; storage then moves that file into place.
DATA_UPLOAD_MAX_MEMORY_SIZE = 10 * 1024 * 1024
FILE_UPLOAD_MAX_MEMORY_SIZE = 10 * 1024 * 1024
# A running job renews its claim every CUTROOM_CLAIM_TIMEOUT / 6 seconds; a claim not
# renewed for CUTROOM_CLAIM_TIMEOUT seconds means its process died, and the sweep (every
# CUTROOM_SWEEP_SECONDS) requeues the job.
CUTROOM_CLAIM_TIMEOUT = envint("CUTROOM_CLAIM_TIMEOUT", 30)
CUTROOM_SWEEP_SECONDS = envint("CUTROOM_SWEEP_SECONDS", 15)
# A job still queued this long after it was sent has its message sent again (the broker
# was unreachable at upload time, a queue was purged).
CUTROOM_RESEND_AFTER = envint("CUTROOM_RESEND_AFTER", 15 * 60)
# Workers are restarted when a job waited this long while a worker process sat idle.
CUTROOM_STALL_SECONDS = envint("CUTROOM_STALL_SECONDS", 60)
# Every worker's main process records a heartbeat this often; the health endpoint takes a
# worker not heard of for CUTROOM_HEARTBEAT_STALE seconds to be gone.
CUTROOM_HEARTBEAT_SECONDS = envint("CUTROOM_HEARTBEAT_SECONDS", 15)
CUTROOM_HEARTBEAT_STALE = envint("CUTROOM_HEARTBEAT_STALE", 60)
# The health endpoint calls a similar-clip index stale when a library segment has waited
# this long to be indexed (searches still find it: they read newer segments from the rows).
CUTROOM_INDEX_STALE_SECONDS = envint("CUTROOM_INDEX_STALE_SECONDS", 900)
# After a review submit or gold save, a take of joints of at most this many joint positions
# (joints × frames) has its library rows built and described in the request; a longer one,
# and every take of points, by a worker's job (`refresh_library`), so the request (which on
# SQLite holds the database's write lock) answers at once and the rows appear when the job
# has run. On the embedded default that job runs on the worker `up` starts beside the web
# server, like every other job; 0 sends every capture's rows to a worker.
CUTROOM_DESCRIBE_INLINE = envint("CUTROOM_DESCRIBE_INLINE", 500_000)
# After this many claims a job that keeps killing its worker is marked failed.
CUTROOM_MAX_ATTEMPTS = envint("CUTROOM_MAX_ATTEMPTS", 3)
# FBX uploads are read by Blender on this queue, served by its own worker (`make up`, compose).
CUTROOM_CONVERT_QUEUE = os.environ.get("CUTROOM_CONVERT_QUEUE") or "convert"
# Seconds Celery lets one conversion run before killing its process (Blender itself is stopped
# after MOTIONLIB_BLENDER_TIMEOUT, 300 s by default; this is the backstop).
CUTROOM_CONVERT_TIME_LIMIT = envint("CUTROOM_CONVERT_TIME_LIMIT", 420)
# Set on the convert worker: its pool processes load Blender as they start.
CUTROOM_CONVERT_WORKER = envbool("CUTROOM_CONVERT_WORKER", False)
CUTROOM_FRAMES_PER_REQUEST = 5000
# What one capture may hold, checked before its frames are allocated (motionlib.take.Limits;
# unset means motionlib's default, given in .env.example).
CUTROOM_MAX_JOINTS = envint("CUTROOM_MAX_JOINTS", None)
CUTROOM_MAX_FRAMES = envint("CUTROOM_MAX_FRAMES", None)
CUTROOM_MAX_FRAME_VALUES = envint("CUTROOM_MAX_FRAME_VALUES", None)
CUTROOM_MAX_JOINT_FRAMES = envint("CUTROOM_MAX_JOINT_FRAMES", None)
CUTROOM_MAX_EXPANSION = envint("CUTROOM_MAX_EXPANSION", None)
# One /frames/ answer carries at most this many joint positions (frames × joints).
CUTROOM_JOINT_FRAMES_PER_REQUEST = 250_000
# Frames and signals answers: at most this many built at once per web process (0: no
# limit), a waiting request gives up after CUTROOM_HEAVY_WAIT s (429); built answers kept
# per process up to CUTROOM_ANSWER_CACHE_MB (0: none). See segmentation/api/common/heavy.py.
CUTROOM_HEAVY_REQUESTS = envint("CUTROOM_HEAVY_REQUESTS", 1)
CUTROOM_HEAVY_WAIT = envint("CUTROOM_HEAVY_WAIT", 60)
CUTROOM_ANSWER_CACHE_MB = envint("CUTROOM_ANSWER_CACHE_MB", 64)
# Requests about a capture of at least CUTROOM_LARGE_TAKE_FRAMES frames (about 14 minutes
# at 120 fps), and the other requests of their client for CUTROOM_BULK_LINGER s, run at most
# CUTROOM_BULK_REQUESTS at a time per web process (0: no lane), at most CUTROOM_BULK_QUEUE
# in hand per process and CUTROOM_BULK_PER_CLIENT per client (then 429), so they never slow
# down other people's requests. See cutroom/lanes.py.
CUTROOM_LARGE_TAKE_FRAMES = envint("CUTROOM_LARGE_TAKE_FRAMES", 100_000)
CUTROOM_BULK_LINGER = envint("CUTROOM_BULK_LINGER", 10)
CUTROOM_BULK_REQUESTS = envint("CUTROOM_BULK_REQUESTS", 1)
CUTROOM_BULK_QUEUE = envint("CUTROOM_BULK_QUEUE", 24)
CUTROOM_BULK_PER_CLIENT = envint("CUTROOM_BULK_PER_CLIENT", 8)
# The bulk lane's own web server (make up starts it, niced): its Unix socket, and how long
# a request handed to it may take. Unset: each process serves its bulk requests itself.
CUTROOM_BULK_SOCKET = os.environ.get("CUTROOM_BULK_SOCKET", "")
CUTROOM_BULK_TIMEOUT = envint("CUTROOM_BULK_TIMEOUT", 300)
# A project's model retrains this many seconds after a review submit or gold save;
# submits made meanwhile join the same training.
CUTROOM_RETRAIN_DELAY = envint("CUTROOM_RETRAIN_DELAY", 10)
# Time limits per job (seconds): past the soft limit the job fails with a message; past
# soft + CUTROOM_TIME_LIMIT_GRACE its process is killed and the job fails at once (the same
# input would run as long again). Ingest includes the default detection run.
CUTROOM_INGEST_TIME_LIMIT = envint("CUTROOM_INGEST_TIME_LIMIT", 600)
CUTROOM_DETECT_TIME_LIMIT = envint("CUTROOM_DETECT_TIME_LIMIT", 300)
CUTROOM_RETRAIN_TIME_LIMIT = envint("CUTROOM_RETRAIN_TIME_LIMIT", 600)
CUTROOM_SUGGEST_TIME_LIMIT = envint("CUTROOM_SUGGEST_TIME_LIMIT", 900)
CUTROOM_TIME_LIMIT_GRACE = envint("CUTROOM_TIME_LIMIT_GRACE", 30)
# Memory (MB) a job may take beyond what its pool process holds when it starts (0 = no
# limit): past it the job meets a MemoryError and fails with a message, instead of the
# machine's OOM killer taking the worker down. Not applied to the convert worker (Blender).
CUTROOM_JOB_MEMORY_MB = envint("CUTROOM_JOB_MEMORY_MB", 0)
# Quotas (0 = no limit): uploads per user per hour (each animation of an FBX counts),
# stored MB per project and per user, detection runs queued or running at once per project
# and started by one person across projects.
CUTROOM_UPLOADS_PER_HOUR = envint("CUTROOM_UPLOADS_PER_HOUR", 120)
CUTROOM_PROJECT_STORAGE_MB = envint("CUTROOM_PROJECT_STORAGE_MB", 20 * 1024)
CUTROOM_USER_STORAGE_MB = envint("CUTROOM_USER_STORAGE_MB", 10 * 1024)
CUTROOM_PROJECT_ACTIVE_RUNS = envint("CUTROOM_PROJECT_ACTIVE_RUNS", 4)
CUTROOM_USER_ACTIVE_RUNS = envint("CUTROOM_USER_ACTIVE_RUNS", 4)

# Celery. No result backend: a job's state is its row (status, error, timings).
# The embedded default's broker is one SQLite file (cutroom.broker): no server, and a
# message is only deleted once its job is acknowledged.
CELERY_BROKER_URL = os.environ.get("CELERY_BROKER_URL") or "sqlite://localhost//"
CELERY_BROKER_DIR = Path(os.environ.get("CELERY_BROKER_DIR") or VAR_DIR / "broker")
CELERY_TASK_IGNORE_RESULT = True
# Separate deployments (or test sessions) can share one Redis by using their own queue.
CELERY_TASK_DEFAULT_QUEUE = os.environ.get("CELERY_QUEUE") or "celery"
# A job is acknowledged only once it finished and is given back if its worker dies, so a
# killed worker never loses an upload; the claim on the row stops double work.
CELERY_TASK_ACKS_LATE = True
CELERY_TASK_REJECT_ON_WORKER_LOST = True
CELERY_WORKER_PREFETCH_MULTIPLIER = 1
CELERY_BROKER_CONNECTION_RETRY_ON_STARTUP = True
if CELERY_BROKER_URL.startswith("sqlite"):
    # A message held by a consumer that stopped renewing it (killed) is handed out
    # again after this many seconds; a live consumer renews it however long its job runs.
    CELERY_BROKER_TRANSPORT_OPTIONS = {
        "path": str(CELERY_BROKER_DIR / "broker.sqlite3"),
        "visibility_timeout": envint("CELERY_VISIBILITY_TIMEOUT", 60),
        "polling_interval": float(os.environ.get("CELERY_BROKER_POLL_SECONDS") or 0.1),
    }
else:
    # Redis gives an unacknowledged job back after this many seconds.
    CELERY_BROKER_TRANSPORT_OPTIONS = {
        "visibility_timeout": envint("CELERY_VISIBILITY_TIMEOUT", 3600),
    }
CELERY_BEAT_SCHEDULE = {
    "sweep-stale-claims": {"task": "segmentation.tasks.sweep", "schedule": float(CUTROOM_SWEEP_SECONDS)},
}

REST_FRAMEWORK = {
    "DEFAULT_AUTHENTICATION_CLASSES": [
        # First, so an anonymous call gets 401 with "WWW-Authenticate: Token", not 403.
        "accounts.authentication.ExpiringTokenAuthentication",
        # Its CSRF check comes before any body is parsed (a text/plain post is a 403).
        "accounts.authentication.CsrfFirstSessionAuthentication",
    ],
    "DEFAULT_PERMISSION_CLASSES": ["rest_framework.permissions.IsAuthenticated"],
    # Bounded nesting and numbers in every JSON body (see segmentation.api.common.parsers).
    "DEFAULT_PARSER_CLASSES": [
        "segmentation.api.common.parsers.BoundedJSONParser",
        "rest_framework.parsers.FormParser",
        "segmentation.api.common.parsers.UploadParser",
    ],
    "DEFAULT_SCHEMA_CLASS": "drf_spectacular.openapi.AutoSchema",
    "EXCEPTION_HANDLER": "segmentation.api.common.errors.exception_handler",
    "UNAUTHENTICATED_USER": "django.contrib.auth.models.AnonymousUser",
}
SPECTACULAR_SETTINGS = {
    "TITLE": "Cutroom API",
    "DESCRIPTION": "Motion-capture takes, candidate cuts, reviews. See docs/api.md.",
    "VERSION": "1",
    "SERVE_INCLUDE_SCHEMA": False,
    "SWAGGER_UI_DIST": "SIDECAR",
    "SWAGGER_UI_FAVICON_HREF": "SIDECAR",
    "REDOC_DIST": "SIDECAR",
    # Request and answer components apart, so that an answer's fields are all required
    # (frontend/src/api/schema.d.ts is generated from this schema).
    "COMPONENT_SPLIT_REQUEST": True,
    "POSTPROCESSING_HOOKS": [
        "drf_spectacular.hooks.postprocess_schema_enums",
        "segmentation.api.common.schema.answers_have_every_field",
    ],
    "ENUM_NAME_OVERRIDES": {
        "JobStatusEnum": "segmentation.models.JOB_STATUSES",
        "ReviewStatusEnum": "segmentation.models.Review.STATUSES",
        "RoleEnum": "segmentation.models.ROLES",
        "ReviewStateEnum": "segmentation.api.common.serializers.reviews.REVIEW_STATES",
        "QueueStateEnum": "segmentation.api.assignments.QUEUE_STATES",
        "CaptureStateEnum": "segmentation.api.dashboard.CAPTURE_STATES",
    },
}

LOGGING = {
    "version": 1,
    "disable_existing_loggers": False,
    "handlers": {"console": {"class": "logging.StreamHandler"}},
    "root": {"handlers": ["console"], "level": os.environ.get("LOG_LEVEL", "WARNING")},
}
