"""docker-compose.yml and the Dockerfile, checked without a Docker engine: the compose file
parses, its services wait for healthy dependencies, workers can be scaled, and every
variable it passes to the app is one that the settings actually read."""

import re
from pathlib import Path

import yaml

from tests.segmentation.test_command_up import up_script

REPO = Path(__file__).resolve().parents[2]
APP_SERVICES = ("migrate", "web", "web-bulk", "worker", "convert", "watchdog")
WORKERS = ("worker", "convert")


def compose():
    return yaml.safe_load((REPO / "docker-compose.yml").read_text())


def settings_variables():
    """Names the settings module reads from the environment."""
    text = (REPO / "cutroom" / "settings.py").read_text()
    return set(re.findall(r'(?:environ\.get|env\w+)\(\s*"([A-Z][A-Z0-9_]+)"', text))


def test_it_parses_and_has_the_production_services():
    services = compose()["services"]
    assert set(services) == {"postgres", "redis", *APP_SERVICES}


def test_it_runs_the_app_on_postgresql_and_redis():
    for name in APP_SERVICES:
        env = compose()["services"][name]["environment"]
        assert env["DATABASE_URL"].startswith("postgres://"), name
        assert env["CELERY_BROKER_URL"].startswith("redis://redis:"), name


def test_every_variable_given_to_the_app_is_read_by_the_settings():
    # WEB_CONCURRENCY is gunicorn's; the BLAS thread counts are numpy's libraries'.
    known = settings_variables() | {"WEB_CONCURRENCY"} | set(up_script().SINGLE_THREADED)
    assert {"DATABASE_URL", "SECRET_KEY", "CELERY_BROKER_URL"} <= known
    for name in APP_SERVICES:
        unknown = set(compose()["services"][name]["environment"]) - known
        assert not unknown, f"{name} sets variables nothing reads: {sorted(unknown)}"


def documented():
    return set(re.findall(r"^([A-Z][A-Z0-9_]+)=", (REPO / ".env.example").read_text(), re.M))


def test_every_variable_given_to_the_app_is_documented_in_env_example():
    fixed = set(up_script().SINGLE_THREADED)  # not settings: the workers' BLAS threads
    for name in APP_SERVICES:
        missing = set(compose()["services"][name]["environment"]) - documented() - fixed
        assert not missing, f"{name}: {sorted(missing)}"


def test_every_variable_the_compose_file_reads_is_documented_in_env_example():
    used = set(re.findall(r"\$\{([A-Z][A-Z0-9_]+)", (REPO / "docker-compose.yml").read_text()))
    assert {"SECRET_KEY", "POSTGRES_PASSWORD", "WORKER_CONCURRENCY"} <= used
    assert not used - documented(), sorted(used - documented())


def test_the_secret_key_must_be_set_rather_than_defaulted():
    env = compose()["services"]["web"]["environment"]
    assert env["SECRET_KEY"].startswith("${SECRET_KEY:?")


def test_web_and_workers_start_after_healthy_services_and_migrations():
    services = compose()["services"]
    for name in ("web", "worker", "convert", "watchdog"):
        depends = services[name]["depends_on"]
        assert depends["postgres"]["condition"] == "service_healthy", name
        assert depends["redis"]["condition"] == "service_healthy", name
        assert depends["migrate"]["condition"] == "service_completed_successfully", name
    assert "migrate" not in services["migrate"]["depends_on"]


def test_every_long_running_service_has_a_health_check():
    services = compose()["services"]
    for name in ("postgres", "redis", "web", "web-bulk", "worker", "convert", "watchdog"):
        assert services[name]["healthcheck"]["test"], name


def test_workers_run_single_threaded_blas_as_make_up_does():
    # One job per core per pool process: BLAS threads of their own would oversubscribe it.
    for name in WORKERS:
        env = compose()["services"][name]["environment"]
        assert {k: env.get(k) for k in up_script().SINGLE_THREADED} == up_script().SINGLE_THREADED, name


def test_the_sweep_and_stall_check_run_outside_the_workers():
    # The jobs of a hung or dead worker are requeued by a process that is not a worker,
    # as make up's supervisor does: exactly one watchdog, no scheduler sending the sweep
    # to the workers it should rescue.
    services = compose()["services"]
    watchdog = services["watchdog"]
    assert watchdog["command"][:3] == ["python", "manage.py", "watch_jobs"]
    assert "--concurrency" in watchdog["command"]
    assert "beat" not in services
    assert all("beat" not in " ".join(map(str, service.get("command", [])))
               for service in services.values())
    assert "watch_jobs --once" in " ".join(watchdog["healthcheck"]["test"])


def test_the_worker_can_be_scaled():
    # A fixed container name or a published port would stop `--scale worker=3`.
    worker = compose()["services"]["worker"]
    assert "container_name" not in worker and "ports" not in worker
    assert worker["command"][:4] == ["celery", "-A", "cutroom", "worker"]


def test_web_and_workers_share_the_originals_and_the_database_persists():
    data = compose()
    for name in ("web", "worker"):
        assert "media:/data/media" in data["services"][name]["volumes"], name
    assert "pgdata:/var/lib/postgresql/data" in data["services"]["postgres"]["volumes"]
    assert {"pgdata", "media"} <= set(data["volumes"])


def test_web_hands_requests_about_long_takes_to_a_bulk_lane_server_of_lower_cpu_weight():
    services = compose()["services"]
    web, bulk = services["web"], services["web-bulk"]
    socket = web["environment"]["CUTROOM_BULK_SOCKET"]
    assert bulk["command"][:4] == ["gunicorn", "cutroom.wsgi:application", "--bind", f"unix:{socket}"]
    assert bulk["environment"]["CUTROOM_BULK_SOCKET"] == ""  # it hands nothing on
    shared = {v for v in web["volumes"] if v.endswith(str(Path(socket).parent))}
    assert shared and shared <= set(bulk["volumes"])
    assert bulk["cpu_shares"] < 1024  # web's is the default, 1024
    assert "ports" not in bulk
    # The app runs as its own user: the socket's folder in the image (which a new named
    # volume copies) must be theirs.
    assert f"chown -R cutroom:cutroom /data {Path(socket).parent}" in (REPO / "Dockerfile").read_text()


def test_the_image_builds_the_front_end_and_installs_the_package():
    dockerfile = (REPO / "Dockerfile").read_text()
    assert "npm ci" in dockerfile and "npm run build" in dockerfile
    assert "COPY --from=frontend" in dockerfile and "frontend/dist" in dockerfile
    runs = [line for line in dockerfile.replace("\\\n", " ").splitlines()
            if line.startswith("RUN ")]
    install = next(run for run in runs if "pip install" in run)
    # motionlib's C parts are compiled in the image, never copied from the host.
    assert "gcc" in install and "pip install -e ." in install
    ignored = (REPO / ".dockerignore").read_text().split()
    assert {".venv", "frontend/node_modules", "var", ".env", "*.so", "build"} <= set(ignored)
