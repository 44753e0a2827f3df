"""A kombu transport on one SQLite file: the embedded default's broker.

It needs no server, and it cannot lose a message:

- a message is one row, written in one transaction (a reader never sees half of it);
- taking a message reserves its row (``BEGIN IMMEDIATE``: two consumers never take the
  same one) for ``visibility_timeout`` seconds, and only the acknowledgement deletes it;
- a consumer renews the reservations of the messages it holds while it is alive, so a
  long job is not handed out twice; a consumer that dies (SIGKILL, power loss) stops
  renewing and its messages are handed out again once their reservation runs out;
- a message given back (a pool process died, the worker stopped) is visible at once.

Celery's ``task_acks_late`` makes that an at-least-once delivery; the claims on the job
rows (``segmentation.models.ClaimQuerySet``) make a second delivery harmless.

Counters per queue (sent, acknowledged) let an operator, and the soak benchmark, check
that every message sent was processed: ``python -m cutroom.broker <file>``.
"""

import json
import os
import sqlite3
import sys
import threading
import time
from contextlib import contextmanager
from queue import Empty

from kombu.transport import virtual
from kombu.utils.encoding import bytes_to_str

SCHEMA = """
CREATE TABLE IF NOT EXISTS message (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    queue TEXT NOT NULL,
    payload TEXT NOT NULL,
    sent_at REAL NOT NULL,
    reserved_until REAL NOT NULL DEFAULT 0,
    deliveries INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS message_ready ON message (queue, reserved_until, id);
CREATE TABLE IF NOT EXISTS binding (
    exchange TEXT NOT NULL, routing_key TEXT NOT NULL, pattern TEXT NOT NULL,
    queue TEXT NOT NULL, PRIMARY KEY (exchange, routing_key, pattern, queue)
);
CREATE TABLE IF NOT EXISTS counter (
    queue TEXT PRIMARY KEY, sent INTEGER NOT NULL DEFAULT 0, acked INTEGER NOT NULL DEFAULT 0
);
"""


class Database:
    """One SQLite file, a connection per process and thread (a forked pool process or
    a result-handler thread must never share the parent's connection)."""

    def __init__(self, path):
        self.path = str(path)
        self._local = threading.local()
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        self.connection().executescript(SCHEMA)

    def connection(self):
        local = self._local
        if getattr(local, "pid", None) != os.getpid():
            db = sqlite3.connect(self.path, timeout=60, isolation_level=None)
            db.execute("PRAGMA journal_mode=WAL")
            # Every committed message survives a power cut, not just a process kill.
            db.execute("PRAGMA synchronous=FULL")
            local.db, local.pid = db, os.getpid()
        return local.db

    @contextmanager
    def write(self):
        """A transaction holding SQLite's write lock from its first statement."""
        db = self.connection()
        db.execute("BEGIN IMMEDIATE")
        try:
            yield db
        except BaseException:
            db.execute("ROLLBACK")
            raise
        db.execute("COMMIT")

    def read(self, sql, args=()):
        return self.connection().execute(sql, args).fetchall()


class QoS(virtual.QoS):
    """Acknowledging deletes the row; giving a message back makes its row visible."""

    def ack(self, delivery_tag):
        self.channel.database_ack(delivery_tag)
        super().ack(delivery_tag)

    def reject(self, delivery_tag, requeue=False):
        if requeue:
            self.channel.database_release([delivery_tag])
        else:
            self.channel.database_ack(delivery_tag)
        self._quick_ack(delivery_tag)

    def restore_unacked(self):
        self._flush()
        self.channel.database_release(list(self._delivered))
        self._delivered.clear()
        return []

    def held(self):
        self._flush()
        return [tag for tag in self._delivered if tag not in self._dirty]


class Channel(virtual.Channel):
    QoS = QoS
    supports_fanout = True
    _databases = {}
    _databases_lock = threading.Lock()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        options = self.connection.client.transport_options
        self.visibility_timeout = float(options.get("visibility_timeout", 60))
        self._renewed = 0.0
        path = options.get("path") or "broker.sqlite3"
        with self._databases_lock:
            if path not in self._databases:
                self._databases[path] = Database(path)
            self.database = self._databases[path]

    # Messages ---------------------------------------------------------------------------

    def _put(self, queue, message, **kwargs):
        with self.database.write() as db:
            db.execute(
                "INSERT INTO message (queue, payload, sent_at) VALUES (?, ?, ?)",
                (queue, json.dumps(message), time.time()),
            )
            db.execute(
                "INSERT INTO counter (queue, sent) VALUES (?, 1) "
                "ON CONFLICT (queue) DO UPDATE SET sent = sent + 1",
                (queue,),
            )

    def _get(self, queue, timeout=None):
        now = time.time()
        ready = "SELECT id, payload FROM message WHERE queue = ? AND reserved_until < ? " \
                "ORDER BY id LIMIT 1"
        # Look without the write lock first: most polls find nothing.
        if not self.database.read(ready, (queue, now)):
            raise Empty()
        with self.database.write() as db:
            row = db.execute(ready, (queue, now)).fetchone()
            if row is None:
                raise Empty()
            db.execute(
                "UPDATE message SET reserved_until = ?, deliveries = deliveries + 1 "
                "WHERE id = ?",
                (now + self.visibility_timeout, row[0]),
            )
        message = json.loads(row[1])
        # The row id is the delivery tag: the copies of a fanout message share the
        # tag they were published with, but each row is acknowledged on its own.
        message["properties"]["delivery_tag"] = str(row[0])
        return message

    def database_ack(self, delivery_tag):
        with self.database.write() as db:
            deleted = db.execute(
                "DELETE FROM message WHERE id = ? RETURNING queue", (int(delivery_tag),)
            ).fetchone()
            if deleted:
                db.execute("UPDATE counter SET acked = acked + 1 WHERE queue = ?", deleted)

    def database_release(self, delivery_tags):
        if delivery_tags:
            with self.database.write() as db:
                db.executemany(
                    "UPDATE message SET reserved_until = 0 WHERE id = ?",
                    [(int(tag),) for tag in delivery_tags],
                )

    def drain_events(self, timeout=None, callback=None):
        self._renew_reservations()
        return super().drain_events(timeout=timeout, callback=callback)

    def _renew_reservations(self):
        """Keep the messages this consumer holds reserved while it is alive; called on
        every poll, written at most four times per visibility timeout."""
        now = time.time()
        if now - self._renewed < self.visibility_timeout / 4 or self._qos is None:
            return
        self._renewed = now
        held = self._qos.held()
        if held:
            with self.database.write() as db:
                db.executemany(
                    "UPDATE message SET reserved_until = ? WHERE id = ?",
                    [(now + self.visibility_timeout, int(tag)) for tag in held],
                )

    def _size(self, queue):
        return self.database.read("SELECT COUNT(*) FROM message WHERE queue = ?", (queue,))[0][0]

    def _purge(self, queue):
        with self.database.write() as db:
            return db.execute(
                "DELETE FROM message WHERE queue = ? AND reserved_until < ?", (queue, time.time())
            ).rowcount

    def _delete(self, queue, *args, **kwargs):
        with self.database.write() as db:
            db.execute("DELETE FROM message WHERE queue = ?", (queue,))
            db.execute("DELETE FROM binding WHERE queue = ?", (queue,))

    # Bindings (shared by every process, so a broadcast reaches every worker) ------------

    def get_table(self, exchange):
        rows = self.database.read(
            "SELECT routing_key, pattern, queue FROM binding WHERE exchange = ?", (exchange,)
        )
        return [tuple(row) for row in rows]

    def _queue_bind(self, exchange, routing_key, pattern, queue):
        with self.database.write() as db:
            db.execute(
                "INSERT OR IGNORE INTO binding VALUES (?, ?, ?, ?)",
                (exchange, routing_key or "", pattern or "", queue),
            )

    def _put_fanout(self, exchange, message, routing_key, **kwargs):
        for _, _, queue in self.get_table(exchange):
            self._put(queue, message)


class Transport(virtual.Transport):
    Channel = Channel
    polling_interval = 0.1
    driver_type = "sqlite"
    driver_name = "sqlite3"
    implements = virtual.Transport.implements.extend(
        asynchronous=False, exchange_type=frozenset(["direct", "topic", "fanout"])
    )

    def driver_version(self):
        return sqlite3.sqlite_version

    @staticmethod
    def release_all(path):
        """See ``release_all``: reached through kombu's transport registry by those that
        know the broker by its URL only (``manage.py sweep_claims --release-broker``)."""
        return release_all(path)


def statistics(path):
    """Per queue: messages sent, acknowledged, and still waiting (reserved or not)."""
    db = Database(path)
    waiting = dict(db.read("SELECT queue, COUNT(*) FROM message GROUP BY queue"))
    return {
        queue: {"sent": sent, "acked": acked, "waiting": waiting.get(queue, 0)}
        for queue, sent, acked in db.read("SELECT queue, sent, acked FROM counter")
    }


def release_all(path):
    """Make every reserved message visible again (after the only consumer was killed)."""
    with Database(path).write() as db:
        return db.execute("UPDATE message SET reserved_until = 0 WHERE reserved_until > 0").rowcount


if __name__ == "__main__":
    for name, row in sorted(statistics(sys.argv[1]).items()):
        print(bytes_to_str(name), row)
