"""Cutroom settings, read from environment variables only.

With nothing set, Cutroom runs embedded: SQLite and a filesystem Celery broker under
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
    "rest_framework.authtoken",
    "drf_spectacular",
    "segmentation",
]

MIDDLEWARE = [
    "django.middleware.security.SecurityMiddleware",
    "whitenoise.middleware.WhiteNoiseMiddleware",
    "django.contrib.sessions.middleware.SessionMiddleware",
    "django.middleware.common.CommonMiddleware",
    "django.middleware.csrf.CsrfViewMiddleware",
    "django.contrib.auth.middleware.AuthenticationMiddleware",
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
    {"NAME": "django.contrib.auth.password_validation.MinimumLengthValidator"},
]
# Behind a TLS-terminating proxy: trust its X-Forwarded-Proto and send cookies over HTTPS only.
if envbool("BEHIND_TLS_PROXY", False):
    SECURE_PROXY_SSL_HEADER = ("HTTP_X_FORWARDED_PROTO", "https")
SESSION_COOKIE_SECURE = CSRF_COOKIE_SECURE = envbool("SECURE_COOKIES", False)

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

MEDIA_URL = "/media/"
MEDIA_ROOT = Path(os.environ.get("CUTROOM_MEDIA_ROOT") or VAR_DIR / "media")
# The similar-clip vector indexes (segmentation.similar_index); rebuilt from the database.
SIMILAR_INDEX_DIR = Path(os.environ.get("CUTROOM_SIMILAR_INDEX_DIR") or VAR_DIR / "similar")
STORAGES = {
    "default": {
        "BACKEND": os.environ.get(
            "CUTROOM_STORAGE_BACKEND", "django.core.files.storage.FileSystemStorage"
        ),
    },
    "staticfiles": {"BACKEND": "django.contrib.staticfiles.storage.StaticFilesStorage"},
}

CUTROOM_MAX_UPLOAD_MB = envint("CUTROOM_MAX_UPLOAD_MB", 200)
# Django refuses request bodies above this; keep it just over the upload limit so the
# API can answer with its own clear 413 instead of a generic error.
DATA_UPLOAD_MAX_MEMORY_SIZE = 10 * 1024 * 1024
FILE_UPLOAD_MAX_MEMORY_SIZE = 10 * 1024 * 1024
# A claim on a capture or run older than this (seconds) is treated as abandoned.
CUTROOM_CLAIM_TIMEOUT = envint("CUTROOM_CLAIM_TIMEOUT", 15 * 60)
# After this many claims a job that keeps killing its worker is marked failed.
CUTROOM_MAX_ATTEMPTS = envint("CUTROOM_MAX_ATTEMPTS", 3)
CUTROOM_FRAMES_PER_REQUEST = 5000

# Celery. No result backend: a job's state is its row (status, error, timings).
# (the host part only keeps kombu from warning that none was given)
CELERY_BROKER_URL = os.environ.get("CELERY_BROKER_URL") or "filesystem://localhost//"
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
if CELERY_BROKER_URL.startswith("filesystem"):
    # A spool folder shared by the web process and the worker: no broker server needed.
    # Short polling keeps upload -> candidates quick on the embedded default.
    CELERY_BROKER_TRANSPORT_OPTIONS = {
        "data_folder_in": str(CELERY_BROKER_DIR / "queue"),
        "data_folder_out": str(CELERY_BROKER_DIR / "queue"),
        "processed_folder": str(CELERY_BROKER_DIR / "processed"),
        # kombu keeps its exchange table in ./control unless told otherwise.
        "control_folder": str(CELERY_BROKER_DIR / "control"),
        "store_processed": False,
        "polling_interval": float(os.environ.get("CELERY_BROKER_POLL_SECONDS") or 0.1),
    }
else:
    # Redis gives an unacknowledged job back after this many seconds.
    CELERY_BROKER_TRANSPORT_OPTIONS = {
        "visibility_timeout": envint("CELERY_VISIBILITY_TIMEOUT", 3600),
    }
CELERY_BEAT_SCHEDULE = {
    "sweep-stale-claims": {"task": "segmentation.tasks.sweep", "schedule": 60.0},
}

REST_FRAMEWORK = {
    "DEFAULT_AUTHENTICATION_CLASSES": [
        "rest_framework.authentication.SessionAuthentication",
        "rest_framework.authentication.TokenAuthentication",
    ],
    "DEFAULT_PERMISSION_CLASSES": ["rest_framework.permissions.IsAuthenticated"],
    "DEFAULT_SCHEMA_CLASS": "drf_spectacular.openapi.AutoSchema",
    "EXCEPTION_HANDLER": "segmentation.api.errors.exception_handler",
    "UNAUTHENTICATED_USER": "django.contrib.auth.models.AnonymousUser",
}
SPECTACULAR_SETTINGS = {
    "TITLE": "Cutroom API",
    "DESCRIPTION": "Motion-capture takes, candidate cuts, reviews. See docs/api.md.",
    "VERSION": "1",
    "SERVE_INCLUDE_SCHEMA": False,
    "ENUM_NAME_OVERRIDES": {
        "JobStatusEnum": "segmentation.models.JOB_STATUSES",
        "ReviewStatusEnum": "segmentation.models.Review.STATUSES",
    },
}

LOGGING = {
    "version": 1,
    "disable_existing_loggers": False,
    "handlers": {"console": {"class": "logging.StreamHandler"}},
    "root": {"handlers": ["console"], "level": os.environ.get("LOG_LEVEL", "WARNING")},
}
