// Sign and coordinate conventions of lensmith, stated once. Every module follows these; a
// formula taken from a book with other signs is converted where it is used, with a comment.
#pragma once

namespace lensmith::conventions {

// Light travels along +z, from object space to image space. Surfaces are listed object side
// first and numbered from 1 in every user-facing output (surface 0 is never a lens surface).
//
// Radius of curvature R (mm): R > 0 when the centre of curvature lies at +z of the vertex
// (a biconvex lens is R1 > 0, R2 < 0). Curvature c = 1/R (1/mm); c = 0 is a plane.
//
// Thickness t_i (mm): the axial distance from vertex i to vertex i+1; the thickness of the last
// surface is the distance from its vertex to the image plane.
//
// Object distance (mm in the lens model, metres at the user interface): the distance from the
// object plane to the vertex of surface 1, positive for a real object in front of the lens;
// +infinity for an object at infinity.
//
// Output positions: every axial position in machine-readable output (`--json`) is a z coordinate
// in millimetres with z = 0 at the vertex of surface 1 and +z toward the image. Human-readable
// tables may add "from last surface" forms, and say so.
//
// Paraxial rays: y is the ray height (mm), u the ray slope dy/dz (radians in the paraxial limit)
// after a surface, i = u_before + y c the paraxial angle of incidence. Marginal ray: from the
// axial object point through the edge of the entrance pupil (y > 0 at the pupil). Chief ray:
// from the edge of the field through the centre of the entrance pupil (object-space slope > 0
// for a positive field).
//
// Paraxial system matrix (Hecht, Optics, 5th ed., section 6.4, as used by Asberg's method):
// the state of a ray is (n u, y); refraction at a surface of power P = (n' - n) c is
// [[1, -P], [0, 1]] and transfer over t in a medium of index n is [[1, 0], [t / n, 1]].
// The system matrix A = R_k T_{k-1} ... T_1 R_1 maps (n u, y) just before vertex 1 to (n' u', y')
// just after vertex k. det A = 1 and EFL = -1 / a12.
//
// Lagrange invariant H = n (u_chief y_marginal - u_marginal y_chief); positive for a positive
// field and aperture.
//
// Seidel sums follow Welford (as CODE V and ray-optics): a positive, undercorrected singlet has
// S_I > 0.
//
// Wavelengths are in nanometres in vacuum-free "air" terms: glass indices are relative to air at
// 20 C, as in the glass makers' catalogues, and air has n = 1 exactly.

}  // namespace lensmith::conventions
