"""What a similar-clip search may return: the segments of the query's project that the
caller may see, described as the query is, not overlapping it (used by ``search`` and by
``similar.candidates``, which reads its candidates from them)."""

from segmentation.models import LibrarySegment
from segmentation.models.library import STAFF
from segmentation.similar.descriptors import is_bare_points, of_kind


class Scope:
    """Whose search it is: user ``user_id``, whose role in the query's project is
    ``role`` (``LibrarySegment.objects.with_role_of``). They may see the segments of the
    project that the role shows them (``visible_in``), the preferred ones."""

    __slots__ = ("user_id", "role")

    def __init__(self, user_id, role):
        self.user_id, self.role = user_id, role


class Pool:
    """What a search from ``segment`` may return: the segments of ``visible`` (a queryset
    or a ``Scope``) in its project, described as it is, not overlapping it.

    With a ``Scope`` it is also a statement's shape and values (``key``, ``values``:
    ``pool_queryset``'s arguments), so that its SQL is compiled once per shape
    (``segmentation.db.statements``)."""

    def __init__(self, segment, visible):
        self.visible = visible
        self.scoped = isinstance(visible, Scope)
        self.values = {"project_id": segment.project_id, "capture_id": segment.capture_id,
                       "start": segment.start, "stop": segment.stop}
        self.key = (visible.role if self.scoped else None, is_bare_points(segment.capture))
        if self.scoped and visible.role not in STAFF:
            self.values["user_id"] = visible.user_id

    @property
    def db(self):
        return LibrarySegment.objects.db if self.scoped else self.visible.db

    def queryset(self):
        return pool_queryset(self.key, visible=None if self.scoped else self.visible, **self.values)


def pool_queryset(key, project_id, capture_id, start, stop, user_id=None, visible=None):
    """``Pool``'s segments: ``key`` is (role, bare points); ``visible``, when given, is
    the queryset the role would give (the role is then not used)."""
    role, bare_points = key
    if visible is None:
        visible = LibrarySegment.objects.visible_in(project_id, user_id, role).preferred()
    return (visible.filter(of_kind(bare_points), project_id=project_id, profile__isnull=False)
            .exclude(capture_id=capture_id, start__lt=stop, stop__gt=start))
