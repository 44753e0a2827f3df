"""The embedded default's broker (``cutroom.broker``, one SQLite file): no message is
lost, whoever dies, and a message held by a dead consumer is handed out again."""

import contextlib
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from kombu import Connection, Queue

REPO = Path(__file__).resolve().parents[1]
CELERY = Path(sys.executable).with_name("celery")


def connection(path, visibility_timeout=60):
    return Connection(
        "sqlite://localhost//",
        transport_options={"path": str(path), "visibility_timeout": visibility_timeout,
                           "polling_interval": 0.01},
    )


def put(path, *bodies):
    with connection(path) as conn:
        producer = conn.Producer()
        for body in bodies:
            producer.publish(body, routing_key="jobs", declare=[Queue("jobs")])


def take(path, visibility_timeout=60, timeout=2):
    """The next message body and the message (unacknowledged), or None."""
    conn = connection(path, visibility_timeout)
    queue = conn.SimpleQueue("jobs")
    try:
        message = queue.get(timeout=timeout)
    except queue.Empty:
        return None, conn
    return message, conn


def test_it_hands_a_message_to_one_consumer_only(tmp_path):
    put(tmp_path / "b.sqlite3", "one")
    first, conn1 = take(tmp_path / "b.sqlite3")
    second, conn2 = take(tmp_path / "b.sqlite3", timeout=0.5)
    assert first.payload == "one"
    assert second is None


def test_it_deletes_a_message_only_when_it_is_acknowledged(tmp_path):
    put(tmp_path / "b.sqlite3", "one")
    message, conn = take(tmp_path / "b.sqlite3")
    with connection(tmp_path / "b.sqlite3") as other:
        assert other.SimpleQueue("jobs").qsize() == 1
        message.ack()
        assert other.SimpleQueue("jobs").qsize() == 0


def test_it_gives_a_rejected_message_back_at_once(tmp_path):
    put(tmp_path / "b.sqlite3", "one")
    message, conn = take(tmp_path / "b.sqlite3")
    message.requeue()
    again, _ = take(tmp_path / "b.sqlite3", timeout=0.5)
    assert again.payload == "one"


def test_it_releases_every_reserved_message_when_asked_after_its_only_worker_was_killed(tmp_path):
    from cutroom import broker

    put(tmp_path / "b.sqlite3", "one", "two")
    take(tmp_path / "b.sqlite3")
    take(tmp_path / "b.sqlite3")
    assert broker.release_all(tmp_path / "b.sqlite3") == 2
    message, _ = take(tmp_path / "b.sqlite3", timeout=0.5)
    assert message.payload == "one"


def test_it_counts_messages_sent_and_acknowledged(tmp_path):
    from cutroom import broker

    put(tmp_path / "b.sqlite3", "one", "two")
    message, _ = take(tmp_path / "b.sqlite3")
    message.ack()
    assert broker.statistics(tmp_path / "b.sqlite3") == {
        "jobs": {"sent": 2, "acked": 1, "waiting": 1}
    }


CONSUMER = textwrap.dedent("""
    import sys
    from kombu import Connection
    import cutroom.celery  # registers sqlite://
    conn = Connection("sqlite://localhost//", transport_options={
        "path": sys.argv[1], "visibility_timeout": float(sys.argv[2]), "polling_interval": 0.01})
    message = conn.SimpleQueue("jobs").get(timeout=10)
    print("took", message.payload, flush=True)
    while True:  # holds the message, unacknowledged, until killed
        try:
            conn.drain_events(timeout=0.05)
        except Exception:
            pass
""")


def start_consumer(path, visibility_timeout):
    proc = subprocess.Popen(
        [sys.executable, "-c", CONSUMER, str(path), str(visibility_timeout)],
        cwd=REPO, stdout=subprocess.PIPE, text=True,
    )
    assert proc.stdout.readline().startswith("took")
    return proc


def test_it_hands_out_again_a_message_whose_consumer_was_killed(tmp_path):
    put(tmp_path / "b.sqlite3", "one")
    holder = start_consumer(tmp_path / "b.sqlite3", visibility_timeout=1)
    os.kill(holder.pid, signal.SIGKILL)
    holder.wait()
    message, _ = take(tmp_path / "b.sqlite3", timeout=5)
    assert message is not None and message.payload == "one"


def test_it_keeps_a_message_reserved_while_its_consumer_lives(tmp_path):
    put(tmp_path / "b.sqlite3", "one")
    holder = start_consumer(tmp_path / "b.sqlite3", visibility_timeout=1)
    try:
        message, _ = take(tmp_path / "b.sqlite3", timeout=3)  # three visibility timeouts
        assert message is None
    finally:
        holder.kill()
        holder.wait()


PRODUCER = textwrap.dedent("""
    import sys
    from cutroom.celery import app
    name, count = sys.argv[1], int(sys.argv[2])
    with app.producer_or_acquire() as producer:
        for i in range(count):
            app.send_task("celery.accumulate", args=[i], task_id=f"{name}-{i}",
                          producer=producer)
""")


@pytest.mark.slow
def test_it_loses_no_message_from_several_producers_to_a_real_worker(tmp_path):
    producers, per_producer = 4, 1000
    env = {k: v for k, v in os.environ.items() if k not in ("CELERY_BROKER_URL", "CELERY_QUEUE")}
    env.update(CUTROOM_VAR_DIR=str(tmp_path), CELERY_BROKER_POLL_SECONDS="0.01",
               DJANGO_SETTINGS_MODULE="cutroom.settings")
    log = tmp_path / "worker.log"
    worker = subprocess.Popen(
        [str(CELERY), "-A", "cutroom", "worker", "-c", "2", "-l", "INFO",
         "--without-mingle", "--without-gossip", "-n", "soak@%h"],
        cwd=REPO, env=env, stdout=log.open("w"), stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:
        sending = [
            subprocess.Popen([sys.executable, "-c", PRODUCER, f"p{n}", str(per_producer)],
                             cwd=REPO, env=env)
            for n in range(producers)
        ]
        assert [p.wait(300) for p in sending] == [0] * producers
        expected = {f"p{n}-{i}" for n in range(producers) for i in range(per_producer)}
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and len(succeeded(log)) < len(expected):
            assert worker.poll() is None, log.read_text()[-3000:]
            time.sleep(1)
        assert succeeded(log) == expected
        assert "Unrecoverable error" not in log.read_text()
    finally:
        # Only the main process: it stops its pool processes itself.
        worker.terminate()
        try:
            worker.wait(60)
        finally:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(worker.pid, signal.SIGKILL)


def succeeded(log):
    return set(re.findall(r"Task celery\.accumulate\[([^\]]+)\] succeeded", log.read_text()))
