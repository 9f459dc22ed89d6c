//! A rectangular grid with explicit `(u, v)` indexing, for surface control nets and weights.
//!
//! Storage is u-major (`data[i * nv + j]`, `j` fastest): the same order as STEP's
//! `control_points_list` (a list over u of lists over v). IGES 128 lists the *first*
//! index fastest; the exchange layer transposes explicitly, and keeping the indexing in one
//! type makes a transposition bug visible in a non-square test net.

/// A `nu x nv` grid of values, indexed `(i, j)` with `i` along u and `j` along v.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid<T> {
    nu: usize,
    nv: usize,
    data: Vec<T>,
}

impl<T> Grid<T> {
    /// Builds a grid from u-major data; `None` if `data.len() != nu * nv`.
    pub fn from_u_major(nu: usize, nv: usize, data: Vec<T>) -> Option<Self> {
        (nu.checked_mul(nv) == Some(data.len())).then_some(Grid { nu, nv, data })
    }

    /// Builds a grid by calling `f(i, j)` for every cell.
    pub fn from_fn(nu: usize, nv: usize, mut f: impl FnMut(usize, usize) -> T) -> Self {
        let mut data = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                data.push(f(i, j));
            }
        }
        Grid { nu, nv, data }
    }

    /// Number of rows along u.
    pub fn nu(&self) -> usize {
        self.nu
    }

    /// Number of columns along v.
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// The cell `(i, j)`. Panics if out of range (an internal invariant, never input-driven:
    /// callers iterate within `nu()` x `nv()`).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> &T {
        &self.data[i * self.nv + j]
    }

    /// Mutable access to cell `(i, j)`.
    #[inline]
    pub fn get_mut(&mut self, i: usize, j: usize) -> &mut T {
        &mut self.data[i * self.nv + j]
    }

    /// Row `i` (all v for one u index).
    pub fn row(&self, i: usize) -> &[T] {
        &self.data[i * self.nv..(i + 1) * self.nv]
    }

    /// The flat u-major data.
    pub fn as_slice(&self) -> &[T] {
        &self.data
    }

    /// Consumes the grid, returning the flat u-major data.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }

    /// Applies `f` to every cell.
    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Grid<U> {
        Grid {
            nu: self.nu,
            nv: self.nv,
            data: self.data.iter().map(f).collect(),
        }
    }

    /// The transposed grid (u and v swapped).
    pub fn transposed(&self) -> Grid<T>
    where
        T: Clone,
    {
        Grid::from_fn(self.nv, self.nu, |i, j| self.get(j, i).clone())
    }
}
