/* Banded dynamic time warping of one descriptor against many (motionlib._dtw).
 *
 * motionlib.similarity.dtw_distances ranks a shortlist of library segments against a
 * query on every "find similar" request; in numpy that is one array step per
 * anti-diagonal and costs milliseconds, here it is a few tens of microseconds. The
 * recursion is motionlib.similarity's: a (n + 1) x (m + 1) table, row by row, each cell
 * the Euclidean distance of two frames plus the least of its three predecessors, only
 * within the Sakoe-Chiba band (centre i * m / n, half-width given), and the result the
 * last cell divided by n + m (inf when the band admits no path). Only the buffer
 * protocol is used, so building needs no numpy.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdlib.h>

static double one(const double *a, const double *b, Py_ssize_t n, Py_ssize_t m, Py_ssize_t f,
                  Py_ssize_t width, double *acc) {
    Py_ssize_t cols = m + 1;
    for (Py_ssize_t k = 0; k < (n + 1) * cols; k++)
        acc[k] = INFINITY;
    acc[0] = 0.0;
    for (Py_ssize_t i = 1; i <= n; i++) {
        Py_ssize_t centre = (Py_ssize_t)((double)(i * m) / (double)n);
        Py_ssize_t lo = centre - width > 1 ? centre - width : 1;
        Py_ssize_t hi = centre + width < m ? centre + width : m;
        const double *x = a + (i - 1) * f;
        for (Py_ssize_t j = lo; j <= hi; j++) {
            const double *y = b + (j - 1) * f;
            double s = 0.0;
            for (Py_ssize_t c = 0; c < f; c++) {
                double d = x[c] - y[c];
                s += d * d;
            }
            double best = acc[(i - 1) * cols + j - 1];
            double up = acc[(i - 1) * cols + j], left = acc[i * cols + j - 1];
            if (up < best)
                best = up;
            if (left < best)
                best = left;
            acc[i * cols + j] = sqrt(s) + best;
        }
    }
    return acc[n * cols + m] / (double)(n + m);
}

PyDoc_STRVAR(distances_doc,
"distances(a, bs, n, m, n_features, n_items, width, out)\n\n"
"a: n x n_features float64 (C order), bs: n_items x m x n_features float64, out: n_items\n"
"float64 written with the banded DTW distance of a to each item.");

static PyObject *distances(PyObject *self, PyObject *args) {
    Py_buffer a, bs, out;
    Py_ssize_t n, m, f, items, width;
    if (!PyArg_ParseTuple(args, "y*y*nnnnnw*", &a, &bs, &n, &m, &f, &items, &width, &out))
        return NULL;
    PyObject *result = NULL;
    double *acc = NULL;
    if (n < 1 || m < 1 || f < 0 || items < 0 || width < 0
        || a.len != (Py_ssize_t)sizeof(double) * n * f
        || bs.len != (Py_ssize_t)sizeof(double) * items * m * f
        || out.len != (Py_ssize_t)sizeof(double) * items) {
        PyErr_SetString(PyExc_ValueError, "distances: buffer sizes disagree with the shape");
        goto done;
    }
    acc = malloc(sizeof(double) * (size_t)(n + 1) * (size_t)(m + 1));
    if (acc == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    const double *pa = a.buf, *pb = bs.buf;
    double *po = out.buf;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t k = 0; k < items; k++)
        po[k] = one(pa, pb + k * m * f, n, m, f, width, acc);
    Py_END_ALLOW_THREADS
    result = Py_None;
    Py_INCREF(result);
done:
    free(acc);
    PyBuffer_Release(&a);
    PyBuffer_Release(&bs);
    PyBuffer_Release(&out);
    return result;
}

static PyMethodDef methods[] = {
    {"distances", distances, METH_VARARGS, distances_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_dtw", "Banded dynamic time warping of one descriptor against many.",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__dtw(void) { return PyModule_Create(&module); }
