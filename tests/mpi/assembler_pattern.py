"""Run under mpiexec (or alone) by tests/solvers/test_petsc_backend.py: the DistributedAssembler's
pattern and values against scipy's T^T K T on the unknowns, for element groups keyed per
block pair (4-node elements of 3 consecutive dofs per node), a group of permuted local dofs
(no blocks: keyed per entry) and an entry group, with a constraint map that ties dofs with
weights (up to 2 entries per row of T), maps two nodes' dofs to the same unknown and drops
fixed ones. Rank 0 prints a JSON document: whether the patterns are equal, the largest
relative value error, the groups' block sizes and, for every rank, the size of the values
array of an assembly against the entries of its own rows plus the distinct entries of its
share in other ranks' rows (the ones it sends), and its rows of a summed force vector T^T f
against scipy's (their size and largest relative error)."""
import json
import sys

import numpy as np
import scipy.sparse as sp

from tmfem.cli import rank_report
from tmfem.solvers.distributed import DistributedAssembler, comm_world, element_share, mpi_main


def problem():
    """The same model on every rank: full dofs, T, keep, element and entry groups."""
    rng = np.random.default_rng(11)
    m = 7                                        # m x m nodes, (m-1)^2 quads
    nn = m * m
    n = 3 * nn + 2                               # + two extra dofs (say, a bar's top)
    ij = np.arange(nn).reshape(m, m)
    quads = np.stack([ij[:-1, :-1], ij[:-1, 1:], ij[1:, 1:], ij[1:, :-1]], axis=-1).reshape(-1, 4)
    quads = quads[rng.permutation(len(quads))]   # element order unrelated to the numbering
    dofs = (3 * quads[:, :, None] + np.arange(3)).reshape(len(quads), 12)
    # two-node elements with their local dofs permuted (not consecutive: per-entry keys)
    pairs = np.stack([ij[:, :-1].ravel(), ij[:, 1:].ravel()], axis=1)[::3]
    perm = [2, 0, 1, 5, 3, 4]
    dofs2 = (3 * pairs[:, :, None] + np.arange(3)).reshape(len(pairs), 6)[:, perm]
    # T (n, nr): identity on most dofs; node 0's dofs = 0.5 (extra a) + 0.25 (own reduced dof);
    # node 1's x dof is node 2's x dof (two blocks on one unknown); dofs of node 3 fixed
    nr = n
    rows, cols, vals = list(range(n)), list(range(n)), [1.0] * n
    for c in range(3):
        vals[c] = 0.25
        rows.append(c), cols.append(3 * nn + (c % 2)), vals.append(0.5)
    cols[3] = 6
    T = sp.csr_matrix((vals, (rows, cols)), shape=(n, nr))
    keep = np.ones(nr, bool)
    keep[9:12] = False                           # node 3
    keep[3] = False                              # node 1's own x (no full dof maps to it now)
    Ke = rng.standard_normal((len(quads), 12, 12))
    K2 = rng.standard_normal((len(pairs), 6, 6))
    ent = rng.integers(0, n, size=(60, 2))
    ev = rng.standard_normal(60)
    return n, T, keep, [(dofs, Ke), (dofs2, K2)], (ent, ev)


def main():
    comm = comm_world()
    n, T, keep, elements, (ent, ev) = problem()
    groups, values = [], []
    for dofs, Ke in elements:
        s = element_share(len(dofs), comm)
        groups.append((dofs[s], "element"))
        values.append(Ke[s])
    s = element_share(len(ent), comm)
    groups.append((ent[s], "entry"))
    values.append(ev[s])
    asm = DistributedAssembler(groups, n, T=T, keep=keep, comm=comm)
    A = asm.scipy(asm.matrix(*values))
    # reference: scipy's sum of all element matrices and entries, mapped by T; its pattern
    # from the same with unit values and |T| (no cancellation)
    K = sp.csr_matrix((n, n))
    S = sp.csr_matrix((n, n))
    for dofs, Ke in elements:
        r = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
        c = np.tile(dofs, (1, dofs.shape[1])).ravel()
        K = K + sp.csr_matrix((Ke.ravel(), (r, c)), shape=(n, n))
        S = S + sp.csr_matrix((np.ones(r.size), (r, c)), shape=(n, n))
    K = K + sp.csr_matrix((ev, (ent[:, 0], ent[:, 1])), shape=(n, n))
    S = S + sp.csr_matrix((np.ones(len(ev)), (ent[:, 0], ent[:, 1])), shape=(n, n))
    ref = (T.T @ K @ T).tocsr()[keep][:, keep]
    pat = (abs(T).T @ S @ abs(T)).tocsr()[keep][:, keep]
    pat.sort_indices()
    A.sort_indices()
    same = bool(np.array_equal(A.indptr, pat.indptr) and np.array_equal(A.indices, pat.indices))
    err = float(abs(A - ref).max() / abs(ref).max())
    # this rank's share alone, mapped the same way: its entries in rows it does not own
    S_mine = sp.csr_matrix((n, n))
    for (dofs, _), (gdofs, _) in zip(elements, groups):
        r = np.repeat(gdofs, gdofs.shape[1], axis=1).ravel()
        c = np.tile(gdofs, (1, gdofs.shape[1])).ravel()
        S_mine = S_mine + sp.csr_matrix((np.ones(r.size), (r, c)), shape=(n, n))
    e = groups[-1][0]
    S_mine = S_mine + sp.csr_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    mine = (abs(T).T @ S_mine @ abs(T)).tocsr()[keep][:, keep]
    sent = mine.nnz - mine[asm.lo:asm.hi].nnz
    buffers = comm.allgather([int(asm._nu), int(pat[asm.lo:asm.hi].nnz + sent)])
    # a force vector: each rank contributes its share of the element forces, and receives
    # its rows of T^T f on the unknowns (the rows of its matrix rows)
    fe = np.random.default_rng(5).standard_normal(elements[0][0].shape)
    s = element_share(len(fe), comm)
    f_mine = np.bincount(elements[0][0][s].ravel(), weights=fe[s].ravel(), minlength=n)
    f_all = np.bincount(elements[0][0].ravel(), weights=fe.ravel(), minlength=n)
    rows = asm.vector(f_mine)
    f_ref = (T.T @ f_all)[keep][asm.lo:asm.hi]
    vec = comm.allgather([rows.size, f_ref.size, float(np.abs(rows - f_ref).max(initial=0.0)
                                                       / np.abs(T.T @ f_all).max())])
    return json.dumps({"pattern_equal": same, "max_rel": err, "nnz": int(A.nnz),
                       "block_sizes": [g.block_size for g in asm._groups], "buffers": buffers,
                       "vector": vec, "N": int(keep.sum())})


if __name__ == "__main__":
    sys.exit(mpi_main(main, report=rank_report()))
