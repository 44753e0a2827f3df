"""Simultaneous requests from threads of one process, as a threaded web server serves them."""

import threading

from django.db import connection


def at_once(requests, timeout=60):
    """Call each of ``requests`` (functions of no argument) in its own thread, released
    together; their results, in the order they finished. Each thread closes its
    database connection when done."""
    start = threading.Barrier(len(requests))
    results, errors = [], []

    def one(request):
        try:
            start.wait()
            results.append(request())
        except Exception as exc:  # noqa: BLE001  (reported to the test below)
            errors.append(exc)
        finally:
            connection.close()

    threads = [threading.Thread(target=one, args=(request,)) for request in requests]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout)
    if errors:
        raise errors[0]
    return results
