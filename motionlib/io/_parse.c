/* Exact, C-speed reading of whitespace-separated decimal numbers (motionlib.io._parse).
 *
 * A capture's MOTION section is hundreds of thousands of decimals such as "-17.2528" or
 * "-2.51463e-014". Each one is read as an integer mantissa and a power of ten; when the
 * mantissa has at most 2**53 and the power is within +-22, both are exact doubles and one
 * multiplication or division gives the correctly rounded value (Clinger's fast path), so the
 * result is bit for bit what Python's float() gives. Any other well-formed number goes
 * through PyOS_string_to_double, Python's own correctly rounded conversion. Anything that is
 * not such a number (nan, inf, "1,5", stray text) or is not finite makes the call decline
 * (-1 or the token's index): the Python caller then re-reads the text line by line to say
 * what is wrong and where. Only the buffer protocol is used, so building needs no numpy.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

static const double POW10[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#define MAX_TOKEN 511     /* longer tokens are declined (a %f double is at most ~320) */
#define MAX_DIGITS 19     /* significant digits that always fit a uint64_t */

/* Separators inside a line; '\n' ends it. str.split() agrees on these bytes. */
static inline int is_blank(unsigned char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static inline int is_digit(unsigned char c) { return (unsigned char)(c - '0') < 10; }

/* Python's conversion for what the fast path cannot do exactly; 0 on success. */
static int slow_number(const char *p, const char *end, double *value) {
    char buf[MAX_TOKEN + 1];
    Py_ssize_t n = end - p;
    char *stop;
    if (n > MAX_TOKEN)
        return -1;
    memcpy(buf, p, (size_t)n);
    buf[n] = '\0';
    /* Called with or without the GIL (read_rows lets it go): take it for Python's call. */
    PyGILState_STATE gil = PyGILState_Ensure();
    double v = PyOS_string_to_double(buf, &stop, NULL);
    int failed = v == -1.0 && PyErr_Occurred();
    if (failed)
        PyErr_Clear();
    PyGILState_Release(gil);
    if (failed)
        return -1;
    if (stop != buf + n || !isfinite(v))
        return -1;
    *value = v;
    return 0;
}

#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define SHORT_DECIMALS 1
static const uint64_t POW10_INT[8] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000};

static inline uint64_t load8(const char *p) {
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* How many of the 8 bytes in v (first byte lowest) are digits before the first non-digit. */
static inline int digit_run(uint64_t v) {
    /* A byte is a digit iff its high nibble and that of byte + 6 are both 3; a carry out of
     * a byte >= 0xFA only disturbs bytes after it, which are past the first non-digit. */
    uint64_t t = (v & 0xF0F0F0F0F0F0F0F0ULL) |
                 (((v + 0x0606060606060606ULL) & 0xF0F0F0F0F0F0F0F0ULL) >> 4);
    uint64_t x = t ^ 0x3333333333333333ULL;
    return x ? __builtin_ctzll(x) >> 3 : 8;
}

/* Value of the first n (1-8) digit bytes of v, eight at a time without a loop. */
static inline uint64_t digits_value(uint64_t v, int n) {
    v <<= 8 * (8 - n); /* leading zero bytes: digit 0 after the mask below */
    v = ((v & 0x0F0F0F0F0F0F0F0FULL) * 2561) >> 8;
    v = ((v & 0x00FF00FF00FF00FFULL) * 6553601) >> 16;
    return ((v & 0x0000FFFF0000FFFFULL) * 42949672960001ULL) >> 32;
}

static inline int separator(unsigned char c) { return c == '\n' || is_blank(c); }

/* digits[.digits] with at most 7 digits on each side and a separator after, as nearly every
 * capture writes them, read with word-wide operations instead of a loop per byte (whose exit
 * the CPU mispredicts on every number). Returns the byte after it, or NULL for the general
 * path. Needs 17 readable bytes at p. */
static inline const char *short_decimal(const char *p, double *value) {
    uint64_t v = load8(p);
    int n = digit_run(v);
    if (n == 0 || n == 8)
        return NULL;
    if (separator((unsigned char)p[n])) {
        *value = (double)digits_value(v, n);
        return p + n;
    }
    if (p[n] != '.')
        return NULL;
    uint64_t w = load8(p + n + 1);
    int m = digit_run(w);
    if (m == 0 || m == 8 || !separator((unsigned char)p[n + 1 + m]))
        return NULL;
    /* At most 14 digits: an exact integer, and 10**m is exact, so one rounding. */
    uint64_t mantissa = digits_value(v, n) * POW10_INT[m] + digits_value(w, m);
    *value = (double)mantissa / POW10[m];
    return p + n + 1 + m;
}
#endif

/* Read [+-]digits[.digits][(e|E)[+-]digits] (or [+-].digits...) starting at p; return the
 * byte after it, or NULL to decline. The caller checks that a separator follows. */
static const char *scan_number(const char *p, const char *end, double *value) {
    const char *start = p, *digits;
    int negative = 0;
    uint64_t mantissa = 0;
    long power = 0;
    Py_ssize_t significant;
    if (p < end && (*p == '+' || *p == '-'))
        negative = *p++ == '-';
#ifdef SHORT_DECIMALS
    if (end - p >= 17) {
        const char *after = short_decimal(p, value);
        if (after) {
            if (negative)
                *value = -*value;
            return after;
        }
    }
#endif
    const char *unsigned_start = p;
    while (p < end && *p == '0')  /* leading zeros are not significant */
        p++;
    int seen = p > unsigned_start;
    for (digits = p; p < end && is_digit(*p); p++)
        mantissa = mantissa * 10 + (uint64_t)(*p - '0');
    significant = p - digits;
    seen |= significant > 0;
    if (p < end && *p == '.') {
        const char *fraction = ++p;
        if (significant == 0)  /* 0.000123: zeros after the dot only scale */
            while (p < end && *p == '0')
                p++;
        for (digits = p; p < end && is_digit(*p); p++)
            mantissa = mantissa * 10 + (uint64_t)(*p - '0');
        significant += p - digits;
        power -= p - fraction;
        seen |= p > fraction;
    }
    if (!seen)
        return NULL;
    if (p < end && (*p == 'e' || *p == 'E')) {
        int exp_negative = 0;
        long exponent = 0;
        p++;
        if (p < end && (*p == '+' || *p == '-'))
            exp_negative = *p++ == '-';
        if (p == end || !is_digit(*p))
            return NULL;
        for (; p < end && is_digit(*p); p++)
            if (exponent < 100000)
                exponent = exponent * 10 + (*p - '0');
        power += exp_negative ? -exponent : exponent;
    }
    if (significant > MAX_DIGITS || mantissa > ((uint64_t)1 << 53) || power > 22 ||
        power < -22) {
        if (significant == 0)
            *value = negative ? -0.0 : 0.0;
        else if (slow_number(start, p, value))
            return NULL;
        return p;
    }
    double v = (double)mantissa;
    v = power < 0 ? v / POW10[-power] : v * POW10[power];
    *value = negative ? -v : v;
    return p;
}

PyDoc_STRVAR(read_rows_doc,
"read_rows(data, offset, out, row_length[, stop]) -> int\n\n"
"Read the lines of ``data[offset:stop]`` into ``out`` (a writable float64 buffer), each\n"
"non-blank line holding exactly ``row_length`` numbers. Returns the number of rows read,\n"
"or -1 when a line has another count, a token is not a finite decimal, or there are more\n"
"rows than ``out`` holds. Other threads run meanwhile (the GIL is let go).");

static PyObject *read_rows(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer data, out;
    Py_ssize_t offset, row_length, rows = 0, stop = -1;
    if (!PyArg_ParseTuple(args, "y*nw*n|n", &data, &offset, &out, &row_length, &stop))
        return NULL;
    Py_ssize_t result = -1;
    if (stop < 0)
        stop = data.len;
    if (offset < 0 || offset > stop || stop > data.len || row_length <= 0 ||
        out.len % sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "read_rows: bad offset, stop, row length or buffer");
        goto done;
    }
    const char *p = (const char *)data.buf + offset, *end = (const char *)data.buf + stop;
    double *dst = (double *)out.buf;
    Py_ssize_t capacity = (Py_ssize_t)(out.len / sizeof(double)) / row_length;
    Py_BEGIN_ALLOW_THREADS
    while (p < end) {
        Py_ssize_t count = 0;
        for (;;) {
            while (p < end && is_blank((unsigned char)*p))
                p++;
            if (p == end || *p == '\n')
                break;
            if (count == row_length || rows == capacity)
                goto bad;
            p = scan_number(p, end, dst + rows * row_length + count);
            if (!p || (p < end && *p != '\n' && !is_blank((unsigned char)*p)))
                goto bad;
            count++;
        }
        if (count) {
            if (count != row_length)
                goto bad;
            rows++;
        }
        p++;  /* past the '\n' (or the end) */
    }
    result = rows;
bad:
    Py_END_ALLOW_THREADS
done:
    PyBuffer_Release(&data);
    PyBuffer_Release(&out);
    return PyErr_Occurred() ? NULL : PyLong_FromSsize_t(result);
}

/* Skip blanks and line ends; the start of the next token or end. */
static inline const char *next_token(const char *p, const char *end) {
    while (p < end && (*p == '\n' || is_blank((unsigned char)*p)))
        p++;
    return p;
}

/* Past the blanks at p, which must end the line: the '\n' (or end), else NULL. */
static inline const char *line_end(const char *p, const char *end) {
    while (p < end && is_blank((unsigned char)*p))
        p++;
    return p == end || *p == '\n' ? p : NULL;
}

static inline const char *token_end(const char *p, const char *end) {
    while (p < end && *p != '\n' && !is_blank((unsigned char)*p))
        p++;
    return p;
}

/* Whether the token at p is the decimal integer `expected`; the byte after it in *after. */
static int is_frame_number(const char *p, const char *end, Py_ssize_t expected,
                           const char **after) {
    const char *stop = token_end(p, end);
    Py_ssize_t value = 0;
    *after = stop;
    if (stop == p || stop - p > 18)
        return 0;
    for (; p < stop; p++) {
        if (!is_digit(*p))
            return 0;
        value = value * 10 + (*p - '0');
    }
    return value == expected;
}

PyDoc_STRVAR(read_frames_doc,
"read_frames(data, offset, names, counts, out) -> int\n\n"
"Read AMC frames from ``data[offset:]``: each is a line with its frame number (1, 2, ...\n"
"in turn), then a line per bone of ``names`` (a sequence of bytes) in that order, holding\n"
"the name and ``counts[i]`` numbers (counts: intp buffer); blank lines are skipped. A\n"
"frame's numbers go to one row of ``out`` (float64, rows of sum(counts)). Returns the\n"
"number of frames, or -1 when the text departs from that pattern, a number is not a\n"
"finite decimal, or ``out`` is too small.");

static PyObject *read_frames(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer data, counts, out;
    Py_ssize_t offset, rows = 0, result = -1, width = 0;
    PyObject *names, *seq = NULL;
    if (!PyArg_ParseTuple(args, "y*nOy*w*", &data, &offset, &names, &counts, &out))
        return NULL;
    Py_ssize_t n_bones = counts.len / (Py_ssize_t)sizeof(Py_ssize_t);
    const Py_ssize_t *count = counts.buf;
    seq = PySequence_Fast(names, "read_frames: names must be a sequence of bytes");
    if (!seq)
        goto done;
    if (PySequence_Fast_GET_SIZE(seq) != n_bones || offset < 0 || offset > data.len) {
        PyErr_SetString(PyExc_ValueError, "read_frames: names and counts differ in length");
        goto done;
    }
    for (Py_ssize_t k = 0; k < n_bones; k++) {
        if (!PyBytes_Check(PySequence_Fast_GET_ITEM(seq, k)) || count[k] < 0) {
            PyErr_SetString(PyExc_ValueError, "read_frames: names must be bytes, counts >= 0");
            goto done;
        }
        width += count[k];
    }
    if (width == 0 || out.len % ((Py_ssize_t)sizeof(double) * width)) {
        PyErr_SetString(PyExc_ValueError, "read_frames: out is not rows of sum(counts)");
        goto done;
    }
    Py_ssize_t capacity = out.len / (Py_ssize_t)sizeof(double) / width;
    const char *p = (const char *)data.buf + offset, *end = (const char *)data.buf + data.len;
    double *dst = out.buf;
    for (p = next_token(p, end); p < end; p = next_token(p, end)) {
        if (rows == capacity || !is_frame_number(p, end, rows + 1, &p) || !line_end(p, end))
            goto done;
        for (Py_ssize_t k = 0; k < n_bones; k++) {
            PyObject *name = PySequence_Fast_GET_ITEM(seq, k);
            Py_ssize_t length = PyBytes_GET_SIZE(name);
            p = next_token(p, end);
            if (token_end(p, end) - p != length || memcmp(p, PyBytes_AS_STRING(name), length))
                goto done;
            p += length;
            for (Py_ssize_t i = 0; i < count[k]; i++) {
                while (p < end && is_blank((unsigned char)*p))
                    p++;
                if (p == end || *p == '\n' || !(p = scan_number(p, end, dst++)) ||
                    (p < end && *p != '\n' && !is_blank((unsigned char)*p)))
                    goto done;
            }
            if (!(p = line_end(p, end)))
                goto done;
        }
        rows++;
    }
    result = rows;
done:
    Py_XDECREF(seq);
    PyBuffer_Release(&data);
    PyBuffer_Release(&counts);
    PyBuffer_Release(&out);
    return PyErr_Occurred() ? NULL : PyLong_FromSsize_t(result);
}

static PyMethodDef methods[] = {
    {"read_rows", read_rows, METH_VARARGS, read_rows_doc},
    {"read_frames", read_frames, METH_VARARGS, read_frames_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_parse",
    "Exact, C-speed reading of whitespace-separated decimal numbers.", -1, methods, NULL, NULL,
    NULL, NULL,
};

PyMODINIT_FUNC PyInit__parse(void) { return PyModule_Create(&module); }
