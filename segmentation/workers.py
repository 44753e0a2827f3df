"""How the app reaches its workers without importing Celery: sending a task by name, and
the exception a worker raises inside a job at its soft time limit.

``segmentation.tasks`` connects both (``connect``) when it is imported, which the app
does once it is ready; so the services, the similar-clip index and the label
suggestions send work by task name and never import the tasks module or Celery.
"""

import logging

log = logging.getLogger(__name__)

_send = None
_stopped = ()
_ping = None


def connect(send, stopped, ping=None):
    """``send(task_name, args, options)`` sends task ``segmentation.tasks.<task_name>``;
    ``stopped`` is the exception class a worker raises inside a job at its soft limit;
    ``ping()`` connects to the broker once and returns its transport's name."""
    global _send, _stopped, _ping
    _send, _stopped, _ping = send, (stopped,), ping


def ping_broker():
    """Connect to the broker once (the health check); raises what connecting raises."""
    if _ping is None:
        raise RuntimeError("no broker connected (importing segmentation.tasks connects it)")
    return _ping()


def stopped():
    """The exception classes that mean "the job's soft time limit was reached" (none
    before ``connect``)."""
    return _stopped


def send(task_name, *args, then="the sweep will retry", **options):
    """Send ``segmentation.tasks.<task_name>(*args)`` now. A broker that cannot be reached
    is logged with what happens ``then``, not raised: a job's row stays queued and the sweep
    sends it again later, so an unreachable broker costs a delay, never the request."""
    try:
        if _send is None:
            raise RuntimeError("no broker connected (importing segmentation.tasks connects it)")
        _send(task_name, args, options)
    except Exception:
        log.exception("could not send %s%s; %s", task_name, args, then)
        return False
    return True
