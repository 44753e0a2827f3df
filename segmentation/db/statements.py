"""Querysets compiled once per shape, then run with new values only.

A similar-clip search reads two small things from the database per request, and Django
spent more CPU building and compiling those querysets than the database spent answering
them. A ``Statement`` builds its queryset once with stand-in values, records which
parameter each value fills, and from then on only fills them in and runs the SQL through
Django's cursor (so its query logging, error wrapping and transactions apply).

The queryset stays the one definition of what is read, who may see what included. A
queryset whose SQL would change with a value, rather than pass it as a parameter, is
refused when it is compiled (it is compiled twice, with two sets of stand-ins, and both
must agree on everything but the stand-ins).

Nothing is prepared on the server: PostgreSQL plans each run with its values. A generic
plan of the candidates' statement (``similar.candidates``) scans ~0.4 s where a custom plan
takes 0.5 ms, and a prepared statement may switch to its generic plan after five runs.
"""

import itertools
import threading

from django.db import connections

# Stand-ins: integers in range of every integer column (Django drops a comparison with a
# value out of a column's range as always true or false), which no id, frame or count of a
# statement here reaches; two compilations tell them from constants. A float stand-in is
# one of them plus a quarter, a string one a name no label or user has.
_STAND_IN = itertools.count(2_000_000_001)

# Compiled shapes kept per statement; beyond it they are compiled again (a shape is a
# handful of lengths and names, so a process meets few).
MAX_SHAPES = 1000


def _kind(name, value, lists):
    """What stand-in a value needs: a list (one array parameter), a tuple of n values (one
    parameter each), a float, a string or an integer."""
    if name in lists:
        return "list"
    if isinstance(value, tuple):
        return len(value)
    if isinstance(value, float):
        return "float"
    return "str" if isinstance(value, str) else "int"


def _stand_in(kind):
    if kind == "list":
        return [next(_STAND_IN)]
    if isinstance(kind, int):
        return tuple(next(_STAND_IN) for _ in range(kind))
    value = next(_STAND_IN)
    return value + 0.25 if kind == "float" else f"\x1fstand-in {value}" if kind == "str" else value


class Statement:
    """``build(key, **values)``: a ``values_list`` queryset; ``key`` names its shape
    (everything ``build`` decides in Python rather than passes as a parameter, e.g. a
    role), so each shape is compiled once. Values are integers, floats, strings, tuples of
    them (one parameter each: the tuple's length is part of the shape), or, named in
    ``lists``, lists (each passed as one array parameter, e.g. through ``extra``).
    ``partial``: a shape may leave some of the values unused (``build`` makes one of
    several querysets from the same values).

    ``rows(using, key, **values)`` runs it and returns the rows as ``values_list`` would
    (binary columns may come as bytes rather than memoryviews); ``window=(offset, limit)``
    reads that slice of them. ``count(using, key, cap, **values)`` counts its rows, no
    further than ``cap``. The queryset is not sliced: Django writes a slice into the SQL."""

    def __init__(self, build, lists=(), partial=False):
        self.build, self.lists, self.partial = build, set(lists), partial
        self._compiled = {}
        self._lock = threading.Lock()

    def rows(self, using, key, window=None, **values):
        sql, params, converters = self._prepared(using, key, values)
        if window is not None:
            sql, params = f"{sql} LIMIT %s OFFSET %s", [*params, window[1], window[0]]
        connection = connections[using]
        with connection.cursor() as cursor:
            cursor.execute(sql, params)
            found = cursor.fetchall()
        if not converters:
            return found
        rows = []
        for row in found:
            row = list(row)
            for i, (functions, expression) in converters.items():
                for convert in functions:
                    row[i] = convert(row[i], expression, connection)
            rows.append(tuple(row))
        return rows

    def count(self, using, key, cap, **values):
        sql, params, _ = self._prepared(using, key, values)
        with connections[using].cursor() as cursor:
            cursor.execute(f"SELECT COUNT(*) FROM ({sql} LIMIT %s) counted", [*params, cap])
            return cursor.fetchone()[0]

    def _prepared(self, using, key, values):
        signature = tuple(sorted((name, _kind(name, value, self.lists))
                                 for name, value in values.items()))
        sql, slots, converters = self._sql(using, key, signature)
        params = []
        for name, index, constant, wrap in slots:
            if name is None:
                params.append(constant)
                continue
            value = values[name] if index is None else values[name][index]
            params.append(value if wrap is None else wrap(value))
        return sql, params, converters

    def _sql(self, using, key, signature):
        with self._lock:
            found = self._compiled.get((using, key, signature))
            if found is None:
                if len(self._compiled) >= MAX_SHAPES:
                    self._compiled.clear()
                found = self._compiled[(using, key, signature)] = self._compile(using, key, signature)
            return found

    def _compile(self, using, key, signature):
        """(sql, slots, converters): each parameter's value name (or None), its index in
        a tuple value (or None), the constant it is (or None) and the type its value is
        passed as (or None); the columns' converters (``SQLCompiler.get_converters``)."""
        shapes = []
        for _ in range(2):
            stand_ins = {name: _stand_in(kind) for name, kind in signature}
            queryset = self.build(key, **stand_ins).using(using)
            compiler = queryset.query.get_compiler(using)
            sql, params = compiler.as_sql()
            columns = compiler.select[:compiler.col_count]
            if [alias for _, _, alias in columns] != list(queryset._fields):
                raise TypeError("a statement's columns are not in the order of its values_list")
            shapes.append((sql, params, _flat(stand_ins)))
        # What values_list does to each column (e.g. JSON parsed, 0/1 to a boolean on SQLite).
        converters = compiler.get_converters([expression for expression, _, _ in columns])
        (sql, first, a), (sql_b, second, b) = shapes
        if sql != sql_b or len(first) != len(second):
            raise TypeError("a statement's SQL changes with its values; pass them as parameters")
        slots = []
        for p, q in zip(first, second, strict=True):
            slot = next((s for s in a if _same(p, a[s]) and _same(q, b[s])), None)
            if slot is None and (not _constant(p, q) or any(_same(p, v) for v in a.values())):
                raise TypeError(f"a statement's parameter {p!r} is neither a value nor a constant")
            # Django passes some integers typed (psycopg's Int4, Int8): so are the values.
            wrap = type(p) if slot and type(p) not in (int, float, str, list) else None
            slots.append((*(slot or (None, None)), None if slot else p, wrap))
        missing = {name for name, _ in signature} - {slot[0] for slot in slots}
        if missing and not self.partial:
            raise TypeError(f"a statement does not use {sorted(missing)} as parameters")
        return sql, slots, converters


def _flat(stand_ins):
    """``{(name, index or None): stand-in}``, a tuple's items one by one."""
    flat = {}
    for name, value in stand_ins.items():
        if isinstance(value, tuple):
            flat.update({(name, i): item for i, item in enumerate(value)})
        else:
            flat[(name, None)] = value
    return flat


def _constant(p, q):
    """Whether two compilations passed the same constant (JSON ones are wrapped)."""
    return p == q or (type(p) is type(q) and hasattr(p, "obj") and p.obj == q.obj)


def _same(param, stand_in):
    """Whether ``param`` is the stand-in (a list one by identity: ``extra`` passes it on)."""
    if isinstance(stand_in, list):
        return param is stand_in
    if isinstance(stand_in, str):
        return param == stand_in
    if isinstance(stand_in, float):
        return isinstance(param, float) and param == stand_in
    return isinstance(param, int) and not isinstance(param, bool) and int(param) == stand_in
