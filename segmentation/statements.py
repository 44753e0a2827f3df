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
plan of the candidates' statement (``similar_index``) scans ~0.4 s where a custom plan
takes 0.5 ms, and a prepared statement may switch to its generic plan after five runs.
"""

import itertools
import threading

from django.db import connections

# Stand-ins: integers in range of every integer column (Django drops a comparison with a
# value out of a column's range as always true or false), which no id, frame or count of a
# statement here reaches; two compilations tell them from constants.
_STAND_IN = itertools.count(2_000_000_001)


class Statement:
    """``build(key, **values)``: a ``values_list`` queryset; ``key`` names its shape
    (everything ``build`` decides in Python rather than passes as a parameter, e.g. a
    role), so each shape is compiled once. ``lists``: the names of values that are lists
    (each passed as one array parameter, e.g. through ``extra``).

    ``rows(using, key, **values)`` runs it and returns the rows as ``values_list`` would
    (binary columns may come as bytes rather than memoryviews)."""

    def __init__(self, build, lists=()):
        self.build, self.lists = build, set(lists)
        self._compiled = {}
        self._lock = threading.Lock()

    def rows(self, using, key, **values):
        sql, slots, converters = self._sql(using, key, sorted(values))
        params = [constant if name is None else values[name] if wrap is None else wrap(values[name])
                  for name, constant, wrap in slots]
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

    def _sql(self, using, key, names):
        with self._lock:
            found = self._compiled.get((using, key, *names))
            if found is None:
                found = self._compiled[(using, key, *names)] = self._compile(using, key, names)
            return found

    def _compile(self, using, key, names):
        """(sql, slots, converters): each parameter's value name (or None), the constant
        it is (or None) and the type its value is passed as (or None); the columns'
        converters (``SQLCompiler.get_converters``)."""
        shapes = []
        for _ in range(2):
            stand_ins = {name: [next(_STAND_IN)] if name in self.lists else next(_STAND_IN)
                         for name in names}
            queryset = self.build(key, **stand_ins).using(using)
            compiler = queryset.query.get_compiler(using)
            sql, params = compiler.as_sql()
            columns = compiler.select[:compiler.col_count]
            if [alias for _, _, alias in columns] != list(queryset._fields):
                raise TypeError("a statement's columns are not in the order of its values_list")
            shapes.append((sql, params, stand_ins))
        # What values_list does to each column (e.g. JSON parsed, 0/1 to a boolean on SQLite).
        converters = compiler.get_converters([expression for expression, _, _ in columns])
        (sql, first, a), (sql_b, second, b) = shapes
        if sql != sql_b or len(first) != len(second):
            raise TypeError("a statement's SQL changes with its values; pass them as parameters")
        slots = []
        for p, q in zip(first, second, strict=True):
            name = next((n for n in names if _same(p, a[n]) and _same(q, b[n])), None)
            if name is None and (not _constant(p, q) or any(_same(p, v) for v in a.values())):
                raise TypeError(f"a statement's parameter {p!r} is neither a value nor a constant")
            # Django passes some integers typed (psycopg's Int4, Int8): so are the values.
            wrap = type(p) if name and type(p) not in (int, list) else None
            slots.append((name, None if name else p, wrap))
        missing = set(names) - {name for name, _, _ in slots}
        if missing:
            raise TypeError(f"a statement does not use {sorted(missing)} as parameters")
        return sql, slots, converters


def _constant(p, q):
    """Whether two compilations passed the same constant (JSON ones are wrapped)."""
    return p == q or (type(p) is type(q) and hasattr(p, "obj") and p.obj == q.obj)


def _same(param, stand_in):
    """Whether ``param`` is the stand-in (a list one by identity: ``extra`` passes it on)."""
    if isinstance(stand_in, list):
        return param is stand_in
    return isinstance(param, int) and not isinstance(param, bool) and int(param) == stand_in
