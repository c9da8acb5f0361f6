"""Zero-copy views of a simulation's particle fields, safe against reordering.

A field component lives in C++ as one contiguous array (structure of arrays,
docs/ARCHITECTURE.md "Data model"). ``FieldArray`` shows it to numpy without a
copy. The simulation keeps its particles in an order of its own choosing and
re-sorts them as they move (SPH and gravity runs do, every few steps): a
reorder moves every particle to another index *and* moves each field to new
memory. So a ``FieldArray`` remembers the simulation's ``epoch`` (the order's
counter), the particle count and the memory it was made on, and checks them
before every use: once the particles were reordered or resized it raises
``StaleViewError`` instead of showing another particle's data (or freed
memory). Take a fresh view (``sim.particles.position.x`` again) after stepping.

The one way around the check is a plain numpy array taken from a view
(``np.asarray(view)``, ``view.array``, or numpy functions called on a view):
it is the C++ memory itself, valid until the next step or run, and must not
be kept past it. Keep ``.copy()`` results instead; follow particles by ``id``.
"""

import numpy as np
from numpy.lib.mixins import NDArrayOperatorsMixin


class StaleViewError(RuntimeError):
    """A view of particle fields used after the particles were reordered or resized."""


class FieldArray(NDArrayOperatorsMixin):
    """One component of one particle field as a zero-copy, checked numpy view.

    Indexing (``v[i]``, ``v[a:b]``, ``v[mask]``), assignment (``v[:] = ...``,
    which writes the C++ state), ``len(v)``, arithmetic and numpy functions
    (``v * 2``, ``np.sqrt(v)``, ``np.mean(v)``) all work as on an ndarray and
    check first that the view is still valid (see the module's rule); they
    raise ``StaleViewError`` otherwise. ``v.copy()`` is an independent ndarray.
    Units are the field's (docs/python.md): SI (m, m/s, m/s², kg, kg/m³, Pa)
    for SPH scenes, G = 1 units for gravity scenes. Ids are read-only.
    """

    __slots__ = ("_sim", "_native", "_name", "_component", "_label", "_epoch", "_count", "_pointer", "_array")

    def __init__(self, sim, name, component=0, vector=False):
        native = sim._native
        self._sim = sim
        self._native = native
        self._name = name
        self._component = component
        self._label = f"{name}.{'xyz'[component]}" if vector else name
        self._epoch = native.epoch
        self._count = native.count
        self._array = native.field(name, component)
        self._pointer = native.data_pointer(name, component)

    @property
    def valid(self):
        """True while the particles have not been reordered or resized since the view was made."""
        n = self._native
        return n.epoch == self._epoch and n.count == self._count and n.data_pointer(self._name, self._component) == self._pointer

    def _check(self):
        if not self.valid:
            raise StaleViewError(
                f"the view of '{self._label}' was made at epoch {self._epoch} with {self._count} particles; the "
                f"particles have since been reordered or resized (epoch {self._native.epoch}, {self._native.count} "
                "particles), so index i no longer holds the same particle: take a new view "
                "(sim.particles.<field> again), and follow particles by sim.particles.id")
        return self._array

    @property
    def array(self):
        """The plain ndarray on the C++ memory (checked now; valid only until the next step or run)."""
        return self._check()

    @property
    def name(self):
        """The field's name (``"position"``, ``"density"``, ...)."""
        return self._name

    @property
    def component(self):
        """The component (0, 1, 2 for x, y, z; 0 for a scalar field)."""
        return self._component

    @property
    def epoch(self):
        """The simulation's epoch when the view was made."""
        return self._epoch

    @property
    def shape(self):
        """(n,): one value per particle."""
        return (self._count,)

    @property
    def dtype(self):
        """numpy float32 or float64 (the scene's precision); int32 or uint64 for integer fields and ids."""
        return self._array.dtype

    @property
    def ndim(self):
        """1."""
        return 1

    @property
    def size(self):
        """n, the particle count when the view was made."""
        return self._count

    def __len__(self):
        return self._count

    def __array__(self, dtype=None, copy=None):
        a = self._check()
        if copy:
            return np.array(a, dtype=dtype, copy=True)
        return a if dtype is None else a.astype(dtype, copy=False)

    def __getitem__(self, index):
        return self._check()[index]

    def __setitem__(self, index, value):
        self._check()[index] = value

    def __iter__(self):
        return iter(self._check())

    def copy(self):
        """An independent copy (ndarray) of the current values."""
        return self._check().copy()

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        args = [x._check() if isinstance(x, FieldArray) else x for x in inputs]
        out = kwargs.get("out")
        if out is not None:
            kwargs["out"] = tuple(x._check() if isinstance(x, FieldArray) else x for x in out)
        result = getattr(ufunc, method)(*args, **kwargs)
        if out is not None:  # in place (v += 1): keep the views
            return out[0] if len(out) == 1 else out
        return result

    def __array_function__(self, func, types, args, kwargs):
        def unwrap(x):
            if isinstance(x, FieldArray):
                return x._check()
            if isinstance(x, (list, tuple)):
                return type(x)(unwrap(y) for y in x)
            return x

        return func(*unwrap(args), **{k: unwrap(v) for k, v in kwargs.items()})

    def __repr__(self):
        state = "valid" if self.valid else "STALE"
        return f"<swirl.FieldArray {self._label} ({state}): {self._array if state == 'valid' else '(take a new view)'}>"



class VectorField:
    """A vector field (position, velocity, acceleration, ...): ``.x``, ``.y``, ``.z`` are FieldArrays.

    Each component is a separate contiguous C++ array; ``to_numpy()`` gives the
    usual (n, 3) array as a copy.
    """

    __slots__ = ("_sim", "_name")

    def __init__(self, sim, name):
        self._sim = sim
        self._name = name

    def _get(self, axis):
        return FieldArray(self._sim, self._name, axis, vector=True)

    def _set(self, axis, value):
        # `v.x += a` hands back the view itself (already written in place); anything else is written into it.
        if isinstance(value, FieldArray) and value._name == self._name and value._component == axis:
            value._check()
            return
        self._get(axis)[:] = value

    x = property(lambda self: self._get(0), lambda self, v: self._set(0, v),
                 doc="Component 0 (zero-copy, checked view); assigning writes every particle's value.")
    y = property(lambda self: self._get(1), lambda self, v: self._set(1, v),
                 doc="Component 1 (zero-copy, checked view); assigning writes every particle's value.")
    z = property(lambda self: self._get(2), lambda self, v: self._set(2, v),
                 doc="Component 2 (zero-copy, checked view); assigning writes every particle's value.")

    def __getitem__(self, axis):
        return self._get(axis)

    def __setitem__(self, axis, value):
        self._set(axis, value)

    def to_numpy(self):
        """An (n, 3) copy in storage order (row i is the particle at index i now)."""
        native = self._sim._native
        out = np.empty((native.count, 3), dtype=native.field(self._name, 0).dtype)
        for c in range(3):
            out[:, c] = native.field(self._name, c)
        return out

    def __repr__(self):
        return f"<swirl.VectorField {self._name!r}>"


class Particles:
    """The particle fields of a simulation, by name (``sim.particles``).

    Built-in fields: ``position`` (m), ``velocity`` (m/s), ``acceleration``
    (m/s²), ``acceleration_prev`` (vectors); ``mass`` (kg), ``density``
    (kg/m³), ``pressure`` (Pa) (scalars); ``id`` (uint64, read-only, each
    particle's stable identity). Solvers add fields of their own (e.g.
    gravity's ``potential``); ``names`` lists them all. In G = 1 scenes the
    units are N-body units. Vector fields are ``VectorField`` (``.x``, ``.y``,
    ``.z``); scalar fields ``FieldArray``: zero-copy views checked against
    reordering (module ``swirl._views``). Storage order changes as the
    simulation re-sorts; ``sorted_by_id`` gives copies in id order.
    """

    __slots__ = ("_sim",)

    def __init__(self, sim):
        object.__setattr__(self, "_sim", sim)

    def _info(self):
        return {name: (components, kind, internal) for name, components, kind, internal in self._sim._native.fields()}

    @property
    def names(self):
        """Every field's name (built-in first, then the solvers' in creation order, then ``id``)."""
        return list(self._info())

    def __len__(self):
        return self._sim._native.count

    def __getitem__(self, name):
        info = self._info()
        if name not in info:
            raise KeyError(f"no particle field {name!r} (the fields: {', '.join(info)})")
        return VectorField(self._sim, name) if info[name][0] == 3 else FieldArray(self._sim, name, 0)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(e.args[0]) from None

    def __setattr__(self, name, value):
        raise AttributeError(f"assign to a field's elements instead: sim.particles.{name}[...] = values")

    def __dir__(self):
        return list(super().__dir__()) + self.names

    def copy(self, name):
        """A copy of field ``name`` in storage order: (n,) for scalars, (n, 3) for vectors."""
        field = self[name]
        return field.to_numpy() if isinstance(field, VectorField) else field.copy()

    def sorted_by_id(self, name=None):
        """Copies in particle-id order: of field ``name`` ((n,) or (n, 3)), or a dict of every non-internal field."""
        order = np.argsort(self._sim._native.field("id", 0), kind="stable")
        if name is not None:
            return self.copy(name)[order]
        return {n: self.copy(n)[order] for n, (_, _, internal) in self._info().items() if not internal}

    def __repr__(self):
        return f"<swirl.Particles: {len(self)} particles, fields {', '.join(self.names)}>"
