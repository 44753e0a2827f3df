# Cutroom image: the built front end plus the Python package. One image runs every
# role of docker-compose.yml (migrate, web, worker, convert, watchdog); the command picks the role.

# --- front end: TypeScript -> frontend/dist ---
FROM node:20-bookworm-slim AS frontend
WORKDIR /app/frontend
COPY frontend/package.json frontend/package-lock.json ./
RUN npm ci --no-audit --no-fund
COPY frontend/ ./
RUN npm run build

# --- service ---
FROM python:3.11-slim-bookworm
ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    CUTROOM_VAR_DIR=/data/var \
    CUTROOM_MEDIA_ROOT=/data/media \
    CUTROOM_SIMILAR_INDEX_DIR=/data/media/similar
RUN useradd --create-home --uid 1000 cutroom \
    && mkdir -p /data/var /data/media /run/cutroom \
    && chown -R cutroom:cutroom /data /run/cutroom
WORKDIR /app
COPY --chown=cutroom:cutroom . .
# Editable, so the code, its templates and migrations stay where settings expect them. The
# compiler builds motionlib's C parts (number reader, forward kinematics) and is removed after.
RUN apt-get update && apt-get install -y --no-install-recommends gcc libc6-dev \
    && pip install -e . \
    && apt-get purge -y --auto-remove gcc libc6-dev && rm -rf /var/lib/apt/lists/* \
    && rm -rf frontend/node_modules build
# Blender as a module (FBX), in a virtualenv of its own: bpy pins numpy<2 and is GPL, so it
# runs only as a child process of the convert worker. The X11/GL libraries are what its
# manylinux wheel links against, even headless.
RUN apt-get update && apt-get install -y --no-install-recommends libx11-6 libxrender1 \
        libxxf86vm1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libgomp1 \
    && rm -rf /var/lib/apt/lists/* \
    && python -m venv /opt/bpy && /opt/bpy/bin/pip install -r requirements-bpy.txt
ENV MOTIONLIB_BLENDER_PYTHON=/opt/bpy/bin/python
# ffprobe reads an uploaded reference video's codec, duration and frame rate (without it
# only the container is checked).
RUN apt-get update && apt-get install -y --no-install-recommends ffmpeg \
    && rm -rf /var/lib/apt/lists/*
COPY --from=frontend --chown=cutroom:cutroom /app/frontend/dist frontend/dist
USER cutroom
EXPOSE 8000
# gunicorn reads WEB_CONCURRENCY for its number of worker processes.
CMD ["gunicorn", "cutroom.wsgi:application", "--bind", "0.0.0.0:8000", \
     "--access-logfile", "-", "--error-logfile", "-", "--timeout", "120"]
