"""The clip library's list: the caller's visible segments, filtered, ordered and paged
without counting or sorting a million rows (the query planner behind ``GET /api/segments/``
and its zip export).

``ListQuery`` takes what a request asks; ``ListQuery.parts`` gives the list as ordered
``Part``s, each read in its order from an index; ``page_ids`` and ``capped_count`` read a
page's ids and a bounded count from them; ``page_rows`` the page's rows as the API shows
them.
"""

import functools
import heapq
import itertools
import operator

from django.contrib.auth import get_user_model
from django.db import connections
from django.db.models import Exists, OuterRef, Q

from segmentation.db import statements
from segmentation.db.statements import Statement
from segmentation.errors import Invalid
from segmentation.models import (
    Label,
    LibraryAttributeValue,
    LibrarySegment,
    Membership,
    SegmentAttribute,
)
from segmentation.models.library import projects_by_role
from segmentation.similar import candidates, search

ORDERINGS = {
    "recent": ("-id",), "duration": ("duration", "id"), "-duration": ("-duration", "-id"),
    "agreement": ("agreement", "id"), "-agreement": ("-agreement", "-id"),
    "label": ("label__name", "id"), "capture": ("capture_id", "start", "id"),
}


class ListQuery:
    """What a list request asks (its filters, given by the view) and the caller's memberships.

    ``values``: what its queries pass as parameters (ids, tuples of them, bounds);
    ``shape``: everything else, decided in Python (the order, the gold filter, which
    filters are present, how many projects, labels and label names there are), which says
    what SQL the list runs. The list's queries are built from the two and compiled once
    per shape (``segmentation.db.statements``): building and compiling a page's querysets
    cost more CPU than the database spent answering them.
    """

    def __init__(self, user, ordering="recent", gold=None, project=None, capture=None,
                 annotator=None, min_duration=None, max_duration=None, min_agreement=None,
                 label=None, attributes=()):
        """``annotator`` a user id (``user_named`` finds it from a name); ``label`` a label
        name; ``attributes`` ``(attribute ids, stored text)`` pairs (``attribute_filter``);
        ``None`` leaves a filter out."""
        self.ordering, self.gold = ordering, gold
        v = {"user": user.pk}
        for name, value in (("project", project), ("capture", capture), ("annotator", annotator),
                            ("min_duration", min_duration), ("max_duration", max_duration),
                            ("min_agreement", min_agreement)):
            if value is not None:
                v[name] = value
        staff, annotating = projects_by_role(user)
        if project is not None:
            staff, annotating = [p for p in staff if p == project], [p for p in annotating if p == project]
        v["staff"], v["annotating"] = tuple(staff), tuple(annotating)
        # Nothing matches: no project to see, or no label of the name in them.
        self.empty = not staff and not annotating
        if label:
            # By the ids the name has in the caller's projects, not by joining the label
            # table, so that the filter is a column of the list's indexes.
            labels = label_rows(user, project, label)
            v["labels"] = tuple(pk for _, pk, _ in labels)
            v["label_projects"] = tuple(p for _, _, p in labels)
            self.empty = self.empty or not labels
        for i, (ids, text) in enumerate(attributes):
            # How the filter reads (``segment_filters``) is part of the shape: by the key.
            how = "walk" if common_value(ids, text) else "seek"
            v[f"attribute{i}"], v[f"attribute{i}_{how}"] = tuple(ids), text
            self.empty = self.empty or not ids
        groups = ()
        if self.ordering == "label":
            labels = label_rows(user, project)
            groups = tuple(len(list(group)) for _, group in
                           itertools.groupby(labels, key=operator.itemgetter(0)))
            v["group_labels"] = tuple(pk for _, pk, _ in labels)
            v["group_projects"] = tuple(p for _, _, p in labels)
        self.values, self.db = v, LibrarySegment.objects.db
        self.shape = (self.db, self.ordering, self.gold, groups,
                      tuple(sorted((k, len(x) if isinstance(x, tuple) else None) for k, x in v.items())))

    def parts(self):
        """The list as ``Part``s whose concatenation is it (none when nothing matches)."""
        if self.empty:
            return []
        return [Part(self, i, *layout) for i, layout in enumerate(_layout(self.shape, self.values))]

    def segments(self):
        """The matching segments as one queryset (for an export)."""
        if self.empty:
            return LibrarySegment.objects.none()
        return (_visible(self.values).filter(*segment_filters(self.gold, self.values))
                .order_by(*ORDERINGS[self.ordering]))


def _layout(shape, values):
    """Per part: how many queries it reads, how many it counts, whether it is newest first."""
    found = _LAYOUTS.get(shape)
    if found is None:
        if len(_LAYOUTS) >= statements.MAX_SHAPES:
            _LAYOUTS.clear()
        found = _LAYOUTS[shape] = [(len(p.queries), len(p.counted), p.descending)
                                  for p in ordered_parts(shape, values)]
    return found


_LAYOUTS = {}


class Part:
    """One ordered run of the list: a query, or several merged by id.

    A filter on several labels (one name in several projects) cannot be read in id order
    from one index; one query per label, each pinned to its label's project, can, and
    merging them costs as many ids per label as the page needs.

    An annotator's part is counted run by run (their own segments, the gold ones: see
    ``LibrarySegment.objects.runs_among``), each from an index of its own: on
    PostgreSQL the part's query is one OR, which counts by filtering every segment of the
    projects (~19 ms for 10,000 of them at a million), unless a label filter lets the
    label's index narrow the OR.
    """

    def __init__(self, query, index, n_queries, n_counted, descending):
        self.query, self.index = query, index
        self.n_queries, self.n_counted, self.descending = n_queries, n_counted, descending

    def count(self, cap):
        """How many rows the part holds, counting no further than ``cap``: the rows of its
        counted queries, which share no row and together hold the part's."""
        total = 0
        for j in range(self.n_counted):
            total += COUNTED.count(self.query.db, (self.query.shape, self.index, j),
                                   cap - total, **self.query.values)
            if total >= cap:
                break
        return total

    def ids(self, offset, limit):
        def run(j, window):
            rows = IDS.rows(self.query.db, (self.query.shape, self.index, j), window=window,
                            **self.query.values)
            return [pk for pk, in rows]

        if self.n_queries == 1:
            return run(0, (offset, limit))
        runs = [run(j, (0, offset + limit)) for j in range(self.n_queries)]
        merged = heapq.merge(*runs, reverse=self.descending)
        return list(itertools.islice(merged, offset, offset + limit))


class QueryPart:
    """A ``Part`` as querysets, which the statements are compiled from: ``queries``, read
    in order and merged by id; ``counted``, querysets that share no row and together hold
    the part's (default: its queries)."""

    def __init__(self, queries, descending=False, counted=None, counted_in_order=()):
        self.queries, self.descending = queries, descending
        self.counted = queries if counted is None else counted
        self.counted_in_order = frozenset(counted_in_order)


def _part_query(key, **values):
    shape, index, j = key
    return ordered_parts(shape, values)[index].queries[j].values_list("id", flat=True)


def _counted_query(key, **values):
    shape, index, j = key
    part = ordered_parts(shape, values)[index]
    order = ORDERINGS["recent"] if j in part.counted_in_order else ()
    return part.counted[j].order_by(*order).values_list("id")


def _gold_run_in_order(db, values, runs, labels):
    """Which counted runs of an annotator's newest-first list are counted in id order: on
    SQLite, the gold run (the last of ``runs_among``'s). Counted in no order, SQLite reads
    it from an index of (project, superseded), every segment of the projects, to find the
    few gold ones (12 ms of CPU at 100,000 segments, where gold rows are too few to reach
    the count's cap early); in id order it reads the gold rows alone from
    ``libseg_sqlite_all_gold``, as the page does (``benchmarks/results/library-list-100k.md``)."""
    if labels or not values["annotating"] or not merges_runs(db):
        return ()
    return (len(runs) - 1,)


IDS = Statement(_part_query, partial=True)
COUNTED = Statement(_counted_query, partial=True)


def page_ids(parts, offset, limit):
    """Ids ``offset`` to ``offset + limit`` of the concatenation of the ``parts``.

    A part wholly before the window is only counted, at most ``offset`` rows of it (the
    last part need not be: its window is empty or its rows).
    """
    ids = []
    for index, part in enumerate(parts):
        if len(ids) >= limit:
            break
        if offset and index < len(parts) - 1:
            skipped = part.count(offset)
            if skipped < offset:
                offset -= skipped
                continue
        ids += part.ids(offset, limit - len(ids))
        offset = 0
    return ids


def capped_count(parts, cap):
    """How many rows ``parts`` hold together, counting no further than ``cap + 1``."""
    total = 0
    for part in parts:
        total += part.count(cap + 1 - total)
        if total > cap:
            break
    return total


PAGE_COLUMNS = ("id", "capture_id", "start", "stop", *candidates.SHOWN)


def page_rows(ids):
    """The API fields of segments ``ids``, in that order (one deleted since its id was
    read is left out)."""
    if not ids:
        return []
    rows = PAGE.rows(LibrarySegment.objects.db, None, ids=tuple(ids))
    found = {row[0]: search.api_fields(*row[:4], row[4:]) for row in rows}
    return [found[pk] for pk in ids if pk in found]


PAGE = Statement(lambda key, ids: LibrarySegment.objects.filter(pk__in=ids).values_list(*PAGE_COLUMNS))


def segment_filters(gold, values):
    """The filters of a ``ListQuery``'s ``gold`` and ``values``, as ``Q``s."""
    # ``__in`` rather than ``=``: on SQLite Django writes a boolean filter as ``NOT "column"``,
    # which no index can seek to; ``IN (0)`` is an equality every index here can use.
    if gold is None:
        filters = [Q(superseded__in=[False])]  # LibrarySegment.preferred()
    else:
        filters = [Q(is_gold__in=[gold])]
    for name, field in (("project", "project_id"), ("capture", "capture_id"),
                        ("annotator", "annotator_id")):
        if name in values:
            filters.append(Q(**{field: values[name]}))
    if "labels" in values:
        filters.append(Q(**one_of("label_id", list(values["labels"]))))
    for name, lookup in (("min_duration", "duration__gte"), ("max_duration", "duration__lte"),
                         ("min_agreement", "agreement__gte")):
        if name in values:
            filters.append(Q(**{lookup: values[name]}))
    i = 0
    while f"attribute{i}" in values:
        filters.append(attribute_q(values, i))
        i += 1
    return filters


# A value carried by at least this many library rows is read by walking the list and
# probing each row (``EXISTS``): the page and the capped count find their rows soon. A
# rarer one is sought in the value index first (``id IN``): walking would probe every
# row of the list to find 50 (``benchmarks/results/library-attribute-filter.md``).
COMMON_VALUE_ROWS = 10_000


def common_value(ids, text):
    """Whether attributes ``ids`` carry ``text`` on at least ``COMMON_VALUE_ROWS`` library
    rows (counted from the value index, no further than that)."""
    rows = LibraryAttributeValue.objects.filter(value=text, **one_of("attribute_id", list(ids)))
    return rows[:COMMON_VALUE_ROWS].count() >= COMMON_VALUE_ROWS


def attribute_q(values, i):
    """The filter of the ``i``th attribute of a ``ListQuery``'s ``values``."""
    walk = f"attribute{i}_walk" in values
    text = values[f"attribute{i}_walk" if walk else f"attribute{i}_seek"]
    carried = LibraryAttributeValue.objects.filter(value=text, **one_of("attribute_id", list(values[f"attribute{i}"])))
    if walk:
        return Exists(carried.filter(segment_id=OuterRef("id")))
    return Q(id__in=carried.values("segment_id"))


def one_of(field, values):
    """A filter on ``field`` being one of ``values``: an equality when there is one, which
    SQLite's planner reads as an index prefix that keeps the index's order (an ``IN``, even
    of one value, makes it sort or scan another index instead)."""
    return {field: values[0]} if len(values) == 1 else {f"{field}__in": values}


def _labels_query(key, user, name=None, project=None):
    """The labels of the user's projects, or of the project asked for; those of one name
    (``key`` says which)."""
    labels = Label.objects.filter(project_id__in=Membership.objects.filter(user_id=user)
                                  .values_list("project_id"))
    if project is not None:
        labels = labels.filter(project_id=project)
    if name is not None:
        labels = labels.filter(name=name)
    return labels.order_by("name", "id").values_list("name", "id", "project_id")


LABELS = Statement(_labels_query)
USER_ID = Statement(lambda key, username: get_user_model().objects.filter(username=username)
                    .values_list("id"))


def label_rows(user, project, name=None):
    """``(name, id, project id)`` of the labels of ``user``'s projects (or of ``project``),
    of the name ``name`` if given, by name and id."""
    values = {"user": user.pk}
    if project is not None:
        values["project"] = project
    if name is not None:
        values["name"] = name
    return LABELS.rows(Label.objects.db, None, **values)


def _visible(values):
    """The segments the caller of a ``ListQuery`` sees (``visible_to``)."""
    return LibrarySegment.objects.visible_among(values["staff"], values["annotating"], values["user"])


def ordered_parts(shape, values):
    """The caller's visible segments matching a ``ListQuery`` (its ``shape`` and
    ``values``) as ``QueryPart``s whose concatenation is the list.

    Ordered by label, the list is each label name's segments by id, names in the
    database's order: one part per name, read from the label index in id order, rather
    than the whole library joined to its labels and sorted. Newest first, the list is
    ``newest_first`` of the caller's visible runs, split by label when the label filter
    names a label of several projects (each then read from a label index in id order).
    """
    db, ordering, gold, groups, _ = shape
    filters = segment_filters(gold, values)
    runs = LibrarySegment.objects.runs_among(values["staff"], values["annotating"], values["user"])
    if ordering == "recent":
        labels = list(zip(values["labels"], values["label_projects"], strict=True)) if "labels" in values else []
        # SQLite reads a label of one project from each run's index; PostgreSQL reads one
        # OR, unless it has an annotator's runs (``0022``).
        split = len(labels) > 1 if merges_runs(db) else bool(labels) and len(runs) > 1
        if split:
            # One run per label and visible run, merged by the database when they are few
            # enough for one compound query.
            each = [Q(project_id=project, label_id=pk) for pk, project in labels]
            if len(each) * len(runs) > MAX_MERGED_RUNS:
                per_label = [[run.filter(*filters, q) for run in runs] for q in each]
                return [QueryPart([newest_first(matched, merge=True) for matched in per_label],
                                  descending=True,
                                  counted=[run for matched in per_label for run in matched])]
            runs = [run.filter(q) for q in each for run in runs]
            matched = [run.filter(*filters) for run in runs]
            return [QueryPart([newest_first(matched, merge=True)])]
        matched = [run.filter(*filters) for run in runs]
        # Counted run by run, unless a label narrows them: then the label's index does
        # better for the OR than the runs' indexes do for each run.
        return [QueryPart([newest_first(matched)], counted=None if labels else matched,
                          counted_in_order=_gold_run_in_order(db, values, runs, labels))]
    # An annotator's runs are one OR (``visible_to``) in any other order.
    visible = runs[0] if len(runs) == 1 else _visible(values)
    segments = visible.filter(*filters)
    if ordering == "label":
        labels = iter(zip(values["group_labels"], values["group_projects"], strict=True))
        return [QueryPart(label_queries(segments, list(itertools.islice(labels, size))))
                for size in groups]
    return [QueryPart([segments.order_by(*ORDERINGS[ordering])])]


def label_queries(segments, labels):
    """A label name's part of the list ordered by label: one query per label of that
    name (``(id, project)``), each in id order."""
    return [segments.filter(project_id=project, label_id=pk).order_by("id") for pk, project in labels]


# SQLite reads at most 500 terms of a compound query (SQLITE_MAX_COMPOUND_SELECT).
MAX_MERGED_RUNS = 100


def newest_first(runs, merge=None):
    """The segments of the ``runs`` (``LibrarySegment.objects.runs_among``, filtered),
    newest first: the runs' ``UNION ALL`` when there are several, which the database reads
    as a merge of the runs, each in id order from an index (an annotator's own segments,
    and the gold ones), where ``annotator = me OR gold`` is in id order in
    no index and would be filtered out of every segment of the projects.

    On PostgreSQL the runs are one OR instead: over several projects its indexes give the
    gold run in id order in none of them, so it sorts every gold row of the union (~0.1 s
    at a million segments), where it walks the OR in id order from ``libseg_list_all``;
    a label name several projects share is likewise one ``label_id IN`` filter there.
    ``merge``: a union whatever the database (runs of one label each, which PostgreSQL
    reads in id order from its indexes too)."""
    queries = [run.order_by() for run in runs]
    if len(queries) < 2:
        query = queries[0] if queries else LibrarySegment.objects.none()
        return query.order_by(*ORDERINGS["recent"])
    if not (merges_runs(queries[0].db) if merge is None else merge):
        return functools.reduce(operator.or_, queries).order_by(*ORDERINGS["recent"])
    return queries[0].union(*queries[1:], all=True).order_by(*ORDERINGS["recent"])


def merges_runs(db):
    """Whether the list reads an annotator's runs (and a shared label name's) as a merge
    of runs: on SQLite, whose indexes give each run in id order; not on PostgreSQL
    (``newest_first``)."""
    return connections[db].vendor == "sqlite"


def user_named(username):
    """The id of the user named ``username``; Invalid when there is none."""
    found = USER_ID.rows(get_user_model().objects.db, None, username=username)
    if not found:
        raise Invalid(f"annotator: no user named {username[:150]!r}")
    return found[0][0]


def attribute_filter(user, project, raw):
    """``(attribute ids, stored text)`` of a list filter ``name:value`` over the attributes
    of that name in ``user``'s projects (or ``project``); Invalid names what is wrong."""
    name, colon, value = raw.partition(":")
    name = name.strip()
    if not colon or not name:
        raise Invalid(f"attribute: write name:value (e.g. quality:good), got {raw[:100]!r}")
    found = SegmentAttribute.objects.filter(
        name=name, project_id__in=Membership.objects.filter(user_id=user.pk).values("project_id"))
    if project is not None:
        found = found.filter(project_id=project)
    found = list(found)
    if not found:
        raise Invalid(f"attribute: no attribute named {name[:100]!r} in your projects")
    text, error = None, None
    for attribute in found:
        try:
            text = attribute.parse(value.strip(), "attribute")
            break
        except Invalid as exc:
            error = error or exc
    if text is None:
        raise error or Invalid(f"attribute: {name[:100]!r} needs a value after the ':'")
    return [a.pk for a in found], text


def check_ordering(ordering):
    """``ordering`` when it is one of ``ORDERINGS``; Invalid naming them otherwise."""
    if ordering not in ORDERINGS:
        raise Invalid(f"ordering: must be one of {', '.join(ORDERINGS)}, got {ordering!r}")
    return ordering
