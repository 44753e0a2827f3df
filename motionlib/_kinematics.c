/* Forward kinematics over all frames in one call (motionlib._kinematics).
 *
 * motionlib.kinematics.forward_kinematics turns a Skeleton into flat per-joint arrays
 * (parent, offset, translation columns, rotation axes and columns, ASF axis frame) and calls
 * positions() here, which walks frame by frame and joint by joint with the joint's global
 * rotation and position kept in a small per-joint scratch array, so everything stays in the
 * first-level cache. Conventions are those documented in motionlib/kinematics.py: column
 * vectors, a joint's rotation channels compose in listed order (G <- G @ R_axis(angle)),
 * a child sits at parent position + parent global rotation @ local translation, and an ASF
 * joint's local rotation is C @ R @ C^T with C its axis frame. Angles are degrees.
 *
 * sin and cos come from a table at whole degrees plus short series for the remaining
 * half degree at most (omitted terms below 1e-18), a few ulp from libm and several times
 * faster. Only the buffer protocol is used, so building needs no numpy.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

#define MAX_ROTATIONS 3
#define DEGREE 0.017453292519943295 /* pi / 180 */

static double SIN[360], COS[360];

/* Columns mixed by G @ R_axis(angle): axis X mixes (1, 2), Y (2, 0), Z (0, 1). */
static const int MIXED[3][2] = {{1, 2}, {2, 0}, {0, 1}};

static void sincos_degrees(double degrees, double *s, double *c) {
    if (!isfinite(degrees)) {
        *s = *c = NAN;
        return;
    }
    /* Whole turns are removed exactly (fmod is exact), unlike scaling a large angle to
     * radians first; the remainder beside the nearest whole degree is at most 0.5. */
    double r = fabs(degrees) < 1e9 ? degrees : fmod(degrees, 360.0);
    long whole = (long)(r >= 0 ? r + 0.5 : r - 0.5);
    double x = (r - (double)whole) * DEGREE; /* the difference is exact */
    long k = whole % 360;
    if (k < 0)
        k += 360;
    /* Taylor series to x^7 and x^6: the next terms are below 1e-20 for |x| <= 0.0088. */
    double x2 = x * x;
    double sx = x + x * x2 * (-1.0 / 6 + x2 * (1.0 / 120 - x2 * (1.0 / 5040)));
    double cx = 1 + x2 * (-0.5 + x2 * (1.0 / 24 - x2 * (1.0 / 720)));
    *s = SIN[k] * cx + COS[k] * sx;
    *c = COS[k] * cx - SIN[k] * sx;
}

/* G <- G @ R_axis(angle) for a row-major 3x3 G. */
static inline void turn(double *G, int axis, double c, double s) {
    int i = MIXED[axis][0], k = MIXED[axis][1];
    for (int r = 0; r < 3; r++) {
        double gi = G[3 * r + i], gk = G[3 * r + k];
        G[3 * r + i] = gi * c + gk * s;
        G[3 * r + k] = gk * c - gi * s;
    }
}

/* out = A @ B (transposed B when transpose_b) for row-major 3x3 matrices. */
static inline void matmul(const double *A, const double *B, double *out, int transpose_b) {
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double sum = 0;
            for (int k = 0; k < 3; k++)
                sum += A[3 * r + k] * (transpose_b ? B[3 * c + k] : B[3 * k + c]);
            out[3 * r + c] = sum;
        }
}

typedef struct {
    Py_ssize_t n_frames, n_channels, n_joints;
    const double *channels;     /* (n_frames, n_channels) */
    const Py_ssize_t *parents;  /* (n_joints,), parents before children */
    const double *offsets;      /* (n_joints, 3) */
    const Py_ssize_t *position; /* (n_joints, 3): channel replacing each offset axis, or -1 */
    const Py_ssize_t *rotation; /* (n_joints, MAX_ROTATIONS, 2): (axis, channel), axis -1 = none */
    const double *axes;         /* (n_joints, 3, 3) ASF axis frames, or NULL */
    double *out;                /* (n_frames, n_joints, 3) */
} Layout;

/* Per-call scratch: global rotations, sines and cosines, and which rotation each joint uses. */
typedef struct {
    double *G;               /* 9 per joint: rotations computed this frame */
    double *SC;              /* 2 per rotation slot: sine, cosine */
    const double **global;   /* per joint: its global rotation (G + 9j or an ancestor's) */
    unsigned char *parent;   /* per joint: 1 if some joint is its child */
} Work;

/* One frame of positions into out (n_joints x 3). */
static void frame_positions(const Layout *L, const double *values, Work *W, double *out) {
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    /* Every sine and cosine first: independent of each other, so they overlap in the CPU,
     * where inside the walk each one would wait for its parent's rotation. */
    for (Py_ssize_t slot = 0; slot < L->n_joints * MAX_ROTATIONS; slot++)
        if (L->rotation[2 * slot] >= 0 && W->parent[slot / MAX_ROTATIONS])
            sincos_degrees(values[L->rotation[2 * slot + 1]], W->SC + 2 * slot,
                           W->SC + 2 * slot + 1);
    for (Py_ssize_t j = 0; j < L->n_joints; j++) {
        double t[3], *here = out + 3 * j;
        for (int a = 0; a < 3; a++) {
            Py_ssize_t col = L->position[3 * j + a];
            t[a] = col >= 0 ? values[col] : L->offsets[3 * j + a];
        }
        Py_ssize_t p = L->parents[j];
        const double *Gp = p < 0 ? identity : W->global[p];
        for (int r = 0; r < 3; r++)
            here[r] = (p < 0 ? 0 : out[3 * p + r]) +
                      (p < 0 ? t[r] : Gp[3 * r] * t[0] + Gp[3 * r + 1] * t[1] + Gp[3 * r + 2] * t[2]);
        if (!W->parent[j])
            continue; /* a leaf's rotation moves no joint */
        const Py_ssize_t *rot = L->rotation + 2 * MAX_ROTATIONS * j;
        int moving = 0;
        for (int k = 0; k < MAX_ROTATIONS && rot[2 * k] >= 0; k++)
            moving |= values[rot[2 * k + 1]] != 0;
        if (!moving) { /* zero angles are the identity: share the parent's, exactly */
            W->global[j] = Gp;
            continue;
        }
        double *Gj = W->G + 9 * j;
        if (L->axes)
            matmul(Gp, L->axes + 9 * j, Gj, 0);
        else
            memcpy(Gj, Gp, sizeof(double) * 9);
        const double *sc = W->SC + 2 * MAX_ROTATIONS * j;
        for (int k = 0; k < MAX_ROTATIONS && rot[2 * k] >= 0; k++)
            if (values[rot[2 * k + 1]] != 0)
                turn(Gj, (int)rot[2 * k], sc[2 * k + 1], sc[2 * k]);
        if (L->axes) {
            double tmp[9];
            matmul(Gj, L->axes + 9 * j, tmp, 1);
            memcpy(Gj, tmp, sizeof(tmp));
        }
        W->global[j] = Gj;
    }
}

/* Every index in range and parents before children; 0 when the layout is safe to walk. */
static int check_layout(const Layout *L) {
    for (Py_ssize_t j = 0; j < L->n_joints; j++) {
        if (L->parents[j] >= j || L->parents[j] < -1)
            return -1;
        for (int a = 0; a < 3; a++)
            if (L->position[3 * j + a] >= L->n_channels || L->position[3 * j + a] < -1)
                return -1;
        for (int k = 0; k < MAX_ROTATIONS; k++) {
            Py_ssize_t axis = L->rotation[2 * (MAX_ROTATIONS * j + k)];
            Py_ssize_t col = L->rotation[2 * (MAX_ROTATIONS * j + k) + 1];
            if (axis < -1 || axis > 2 || (axis >= 0 && (col < 0 || col >= L->n_channels)))
                return -1;
        }
    }
    return 0;
}

PyDoc_STRVAR(positions_doc,
"positions(channels, n_frames, n_channels, parents, offsets, position, rotation, axes, out)\n\n"
"World positions of every joint in every frame into ``out`` (float64, n_frames x n_joints\n"
"x 3). channels: float64 (n_frames, n_channels); parents: intp (n_joints,); offsets:\n"
"float64 (n_joints, 3); position: intp (n_joints, 3), channel or -1; rotation: intp\n"
"(n_joints, 3, 2), (axis 0-2, channel) in composition order, axis -1 for none; axes:\n"
"float64 (n_joints, 3, 3) or None.");

/* The layout from the buffers positions() and body_frame() take; 0 when they are
 * consistent and safe to walk, else -1 with a ValueError set. */
static int read_layout(Layout *L, const Py_buffer *ch, const Py_buffer *parents,
                       const Py_buffer *offsets, const Py_buffer *position,
                       const Py_buffer *rotation, const Py_buffer *axes, const char *name) {
    L->n_joints = parents->len / (Py_ssize_t)sizeof(Py_ssize_t);
    Py_ssize_t J = L->n_joints, F = L->n_frames;
    if (L->n_channels < 0 || F < 0 || ch->len != F * L->n_channels * (Py_ssize_t)sizeof(double) ||
        offsets->len != J * 3 * (Py_ssize_t)sizeof(double) ||
        position->len != J * 3 * (Py_ssize_t)sizeof(Py_ssize_t) ||
        rotation->len != J * 2 * MAX_ROTATIONS * (Py_ssize_t)sizeof(Py_ssize_t) ||
        (axes->buf && axes->len != J * 9 * (Py_ssize_t)sizeof(double))) {
        PyErr_Format(PyExc_ValueError, "%s: buffer sizes do not match", name);
        return -1;
    }
    L->channels = ch->buf;
    L->parents = parents->buf;
    L->offsets = offsets->buf;
    L->position = position->buf;
    L->rotation = rotation->buf;
    L->axes = axes->buf;
    if (check_layout(L)) {
        PyErr_Format(PyExc_ValueError, "%s: joint layout out of range", name);
        return -1;
    }
    return 0;
}

/* Scratch for walking L; 0 on success, else -1 with MemoryError set (free_work either way). */
static int alloc_work(const Layout *L, Work *W) {
    Py_ssize_t J = L->n_joints;
    size_t n = (size_t)(J > 0 ? J : 1);
    W->G = PyMem_Malloc(sizeof(double) * (9 + 2 * MAX_ROTATIONS) * n);
    W->global = PyMem_Malloc(sizeof(double *) * n);
    W->parent = PyMem_Calloc(n, 1);
    if (!W->G || !W->global || !W->parent) {
        PyErr_NoMemory();
        return -1;
    }
    W->SC = W->G + 9 * J;
    for (Py_ssize_t j = 0; j < J; j++)
        if (L->parents[j] >= 0)
            W->parent[L->parents[j]] = 1;
    return 0;
}

static void free_work(Work *W) {
    PyMem_Free(W->G);
    PyMem_Free(W->global);
    PyMem_Free(W->parent);
}

/* Release the buffers of a layout (axes only when one was given). */
static void release_layout(Py_buffer *ch, Py_buffer *parents, Py_buffer *offsets,
                           Py_buffer *position, Py_buffer *rotation, Py_buffer *axes) {
    PyBuffer_Release(ch);
    PyBuffer_Release(parents);
    PyBuffer_Release(offsets);
    PyBuffer_Release(position);
    PyBuffer_Release(rotation);
    if (axes->buf)
        PyBuffer_Release(axes);
}

static PyObject *positions(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer ch, parents, offsets, position, rotation, out, axes = {0};
    PyObject *axes_obj;
    Layout L;
    if (!PyArg_ParseTuple(args, "y*nny*y*y*y*Ow*", &ch, &L.n_frames, &L.n_channels, &parents, &offsets,
                          &position, &rotation, &axes_obj, &out))
        return NULL;
    int ok = 0;
    Work W = {0};
    if (axes_obj != Py_None && PyObject_GetBuffer(axes_obj, &axes, PyBUF_SIMPLE) < 0)
        goto done;
    if (read_layout(&L, &ch, &parents, &offsets, &position, &rotation, &axes, "positions"))
        goto done;
    Py_ssize_t J = L.n_joints, F = L.n_frames;
    if (out.len != F * J * 3 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "positions: buffer sizes do not match");
        goto done;
    }
    L.out = out.buf;
    if (alloc_work(&L, &W))
        goto done;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t f = 0; f < F; f++)
        frame_positions(&L, L.channels + f * L.n_channels, &W, L.out + f * J * 3);
    Py_END_ALLOW_THREADS
    ok = 1;
done:
    free_work(&W);
    release_layout(&ch, &parents, &offsets, &position, &rotation, &axes);
    PyBuffer_Release(&out);
    if (!ok)
        return NULL;
    Py_RETURN_NONE;
}

PyDoc_STRVAR(body_frame_doc,
"body_frame(channels, n_frames, n_channels, parents, offsets, position, rotation, axes,\n"
"           chosen, root, left_hip, right_hip, out)\n\n"
"Each frame's ``chosen`` joints relative to the root with the heading removed, then the\n"
"root's height, into ``out`` (float64, n_frames x (3 len(chosen) + 1)): what\n"
"motionlib.features.body_frame_positions gives from positions(), without writing every\n"
"joint of every frame first. chosen: intp joint indices; the rest as for positions().");

static PyObject *body_frame(PyObject *self, PyObject *args) {
    (void)self;
    Py_buffer ch, parents, offsets, position, rotation, chosen, out, axes = {0};
    PyObject *axes_obj;
    Py_ssize_t root, left_hip, right_hip;
    Layout L;
    if (!PyArg_ParseTuple(args, "y*nny*y*y*y*Oy*nnnw*", &ch, &L.n_frames, &L.n_channels, &parents,
                          &offsets, &position, &rotation, &axes_obj, &chosen, &root, &left_hip,
                          &right_hip, &out))
        return NULL;
    int ok = 0;
    Work W = {0};
    double *frame = NULL;
    if (axes_obj != Py_None && PyObject_GetBuffer(axes_obj, &axes, PyBUF_SIMPLE) < 0)
        goto done;
    if (read_layout(&L, &ch, &parents, &offsets, &position, &rotation, &axes, "body_frame"))
        goto done;
    Py_ssize_t J = L.n_joints, F = L.n_frames;
    Py_ssize_t K = chosen.len / (Py_ssize_t)sizeof(Py_ssize_t), width = 3 * K + 1;
    const Py_ssize_t *which = chosen.buf;
    int in_range = root >= 0 && root < J && left_hip >= 0 && left_hip < J && right_hip >= 0 &&
                   right_hip < J;
    for (Py_ssize_t k = 0; k < K; k++)
        in_range &= which[k] >= 0 && which[k] < J;
    if (!in_range || out.len != F * width * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "body_frame: joint index out of range or output size");
        goto done;
    }
    frame = PyMem_Malloc(sizeof(double) * 3 * (size_t)(J > 0 ? J : 1));
    if (!frame) {
        PyErr_NoMemory();
        goto done;
    }
    if (alloc_work(&L, &W))
        goto done;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t f = 0; f < F; f++) {
        frame_positions(&L, L.channels + f * L.n_channels, &W, frame);
        const double *r = frame + 3 * root, *lh = frame + 3 * left_hip, *rh = frame + 3 * right_hip;
        /* The hip axis (left -> right) turned onto +X about Y, as body_frame_positions does
         * (features.heading_cos_sin): the same operations in the same order, all of them
         * correctly rounded, so the same values. */
        double dx = rh[0] - lh[0], dz = rh[2] - lh[2];
        double length = sqrt(dx * dx + dz * dz);
        double c = 1.0, s = 0.0;
        if (!(length == 0)) {
            c = dx / length;
            s = dz / length;
        }
        double *row = (double *)out.buf + f * width;
        for (Py_ssize_t k = 0; k < K; k++) {
            const double *p = frame + 3 * which[k];
            double x = p[0] - r[0], z = p[2] - r[2];
            row[3 * k] = c * x + s * z;
            row[3 * k + 1] = p[1] - r[1];
            row[3 * k + 2] = -s * x + c * z;
        }
        row[3 * K] = r[1];
    }
    Py_END_ALLOW_THREADS
    ok = 1;
done:
    PyMem_Free(frame);
    free_work(&W);
    release_layout(&ch, &parents, &offsets, &position, &rotation, &axes);
    PyBuffer_Release(&chosen);
    PyBuffer_Release(&out);
    if (!ok)
        return NULL;
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"positions", positions, METH_VARARGS, positions_doc},
    {"body_frame", body_frame, METH_VARARGS, body_frame_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kinematics",
    "Forward kinematics over all frames in one call.", -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kinematics(void) {
    for (int k = 0; k < 360; k++) {
        SIN[k] = sin(k * DEGREE);
        COS[k] = cos(k * DEGREE);
    }
    return PyModule_Create(&module);
}
