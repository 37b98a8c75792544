// The uncoated Fresnel transmittance of a traced ray: at each surface, the mean of the s and p
// intensity transmittances for unpolarised light (Born & Wolf, Principles of Optics, sec. 1.5.3), from
// the indices on both sides and the cosines of the angles of incidence and refraction. Mirrors and
// coordinate breaks (the same medium on both sides) transmit 1. What the polynomial fits' transmittance
// map and the pupil amplitude of the MTF and PSF use; coatings are not modelled.
#pragma once

#include <span>

#include <Eigen/Core>

#include "lensmith/trace/sequential_tracer.h"

namespace lensmith {

// One interface, indices n1 (incident side) and n2, cosines of the incidence and refraction angles (>= 0).
double fresnel_transmittance(double n1, double cos1, double n2, double cos2);

// The product over a ray's surface crossings (`path`, as the tracer records it) of each interface's
// transmittance. `direction_before` is the ray's direction before its first crossing. Forward: light goes
// from the medium before each surface into the medium after it; backward (a ray traced from the image
// side, trace_backward): the other way.
double path_transmittance(const SequentialTracer& tracer, const Eigen::Vector3d& direction_before, std::span<const SurfaceHit> path,
                          double wavelength_nm, bool backward = false);

}  // namespace lensmith
