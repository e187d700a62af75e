/*
 * Sheet XML for runs of numeric cells: the workbook writer's fast path
 * (airgun_xl/workbook/columns_sheet.py). Not part of the simulation.
 *
 * Python interface (module airgun_xl.workbook._sheet_xml):
 *   render_cells(column, first_row, values[, style]) -> list of str
 *     '<c r="I5"><v>...</v></c>' for each value (finite float64), rows counted from
 *     first_row (1-based), numbers with 17 significant digits (exact round trip);
 *     with a style index >= 0, '<c r="I5" s="3"><v>...</v></c>'.
 * The pure-Python twin is airgun_xl/workbook/sheet_xml.py; a test compares them.
 */
#define PY_SSIZE_T_CLEAN
#ifndef Py_LIMITED_API
#define Py_LIMITED_API 0x030B0000
#endif
#include <Python.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Sheet XML for a run of numeric cells: the writer's fast path (columns_sheet.py). The text
 * is formatted with the GIL released, so two threads render two columns at once. */
#define CELL_MAX 96

static PyObject *py_render_cells(PyObject *self, PyObject *args)
{
    const char *column;
    Py_ssize_t first_row, n, i, bad = -1, style = -1;
    PyObject *values, *out = NULL;
    Py_buffer view;
    char *text;
    int *lengths;

    if (!PyArg_ParseTuple(args, "snO|n", &column, &first_row, &values, &style))
        return NULL;
    if (strlen(column) > 8)
        return PyErr_Format(PyExc_ValueError, "column name too long");
    if (PyObject_GetBuffer(values, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return NULL;
    if (view.itemsize != sizeof(double) || view.format == NULL || strcmp(view.format, "d")) {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_ValueError, "values must be a float64 buffer");
        return NULL;
    }
    n = view.len / (Py_ssize_t)sizeof(double);
    if (n > PY_SSIZE_T_MAX / CELL_MAX) {
        PyBuffer_Release(&view);
        return PyErr_NoMemory();
    }
    text = malloc((size_t)(n > 0 ? n : 1) * CELL_MAX);
    lengths = malloc((size_t)(n > 0 ? n : 1) * sizeof(int));
    if (text == NULL || lengths == NULL) {
        free(text);
        free(lengths);
        PyBuffer_Release(&view);
        return PyErr_NoMemory();
    }
    Py_BEGIN_ALLOW_THREADS
    for (i = 0; i < n; i++) {
        double x = ((double *)view.buf)[i];
        char *cell = text + i * CELL_MAX;
        int j, len;
        if (!isfinite(x)) {
            bad = i;
            break;
        }
        /* 17 significant digits always read back as the same double */
        if (style >= 0)
            len = snprintf(cell, CELL_MAX, "<c r=\"%s%zd\" s=\"%zd\"><v>%.17g</v></c>",
                           column, first_row + i, style, x);
        else
            len = snprintf(cell, CELL_MAX, "<c r=\"%s%zd\"><v>%.17g</v></c>", column,
                           first_row + i, x);
        for (j = 0; j < len; j++)
            if (cell[j] == ',')
                cell[j] = '.'; /* a caller's setlocale() must not change the XML */
        lengths[i] = len;
    }
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&view);
    if (bad >= 0) {
        PyErr_Format(PyExc_ValueError, "values must be finite (index %zd)", bad);
    } else if ((out = PyList_New(n)) != NULL) {
        for (i = 0; i < n; i++) {
            PyObject *cell = PyUnicode_FromStringAndSize(text + i * CELL_MAX, lengths[i]);
            if (cell == NULL) {
                Py_CLEAR(out);
                break;
            }
            PyList_SetItem(out, i, cell); /* steals the reference */
        }
    }
    free(text);
    free(lengths);
    return out;
}

static PyMethodDef methods[] = {
    {"render_cells", py_render_cells, METH_VARARGS,
     "render_cells(column, first_row, values[, style]) -> list of '<c r=...><v>...</v></c>'"
     " strings"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_sheet_xml",
                                    "Sheet XML of numeric cells (the writer's fast path).", -1,
                                    methods};

PyMODINIT_FUNC PyInit__sheet_xml(void) { return PyModule_Create(&module); }
