#pragma once
/// \file OrnsteinUhlenbeckStep.hpp
/// The exact step of an Ornstein-Uhlenbeck velocity of memory T and unit variance over a time dt,
/// velocity and displacement together (Gillespie 1996, Phys. Rev. E 54, 2084). With u the velocity at
/// the start, xi1 and xi2 independent standard normals:
///   u(t + dt) = decay u + kick xi1,
///   mean velocity over the step = carry u + shared xi1 + own xi2,
/// which reproduces the process's joint Gaussian law of end velocity and displacement for any dt / T:
/// the displacement's variance T^2 (2 tau - 3 + 4 a - a^2) and its covariance T (1 - a)^2 with the end
/// velocity, tau = dt / T, a = exp(-tau). For dt >> T the mean velocity over the step has variance
/// 2 T / dt (diffusion with T, the velocity forgotten within the step); for dt << T it is the start
/// velocity. Scale the noise by sigma for a variance sigma^2.

#include <algorithm>
#include <cmath>

namespace rcfd {

struct OrnsteinUhlenbeckStep {
  double decay = 1.0;   ///< a = exp(-dt / T)
  double kick = 0.0;    ///< sqrt(1 - a^2)
  double carry = 1.0;   ///< T (1 - a) / dt: the start velocity's share of the mean over the step
  double shared = 0.0;  ///< the mean's part of xi1, whose covariance with the end velocity is T (1 - a)^2
  double own = 0.0;     ///< the mean's independent rest of its variance

  static OrnsteinUhlenbeckStep over(double dt, double memory) {
    const double tau = dt / memory;
    const double a = std::exp(-tau);
    const double oneMinusA = -std::expm1(-tau);
    OrnsteinUhlenbeckStep s;
    s.decay = a;
    s.kick = std::sqrt(oneMinusA * (1.0 + a));
    s.carry = oneMinusA / tau;
    // In units of T: c1 = (1 - a)^2 / kick and c2^2 = 2 tau - 3 + 4a - a^2 - c1^2, which cancels to
    // tau^3 / 6 - tau^5 / 60 + O(tau^7) for small tau, where its terms would cancel in double.
    const double c1 = oneMinusA * oneMinusA / s.kick;
    const double c2Squared = tau < 1e-2 ? tau * tau * tau * (1.0 / 6.0 - tau * tau / 60.0)
                                        : 2.0 * tau - 3.0 + 4.0 * a - a * a - c1 * c1;
    s.shared = c1 / tau;
    s.own = std::sqrt(std::max(0.0, c2Squared)) / tau;
    return s;
  }
};

}  // namespace rcfd
