// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "kiseki/coop/triangulation.hpp"

using namespace kiseki;

namespace {

constexpr double kPi = 3.14159265358979323846;

double bearing_to(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  return std::atan2(to.y() - from.y(), to.x() - from.x());
}

// The sample covariance of n triangulations with Gaussian angle noise of SD sigma.
Eigen::MatrixXd monte_carlo(const std::vector<Eigen::Vector3d>& standing, const Eigen::Vector3d& target, bool three_d,
                            double sigma, int n, std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  const int dims = three_d ? 3 : 2;
  std::vector<Eigen::VectorXd> xs;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(dims);
  for (int k = 0; k < n; ++k) {
    std::vector<double> b, e;
    for (const auto& p : standing) {
      const Eigen::Vector3d d = target - p;
      b.push_back(std::atan2(d.y(), d.x()) + noise(gen));
      e.push_back(std::atan2(d.z(), d.head<2>().norm()) + noise(gen));
    }
    Eigen::VectorXd x;
    if (three_d) {
      x = triangulate(standing, b, e).position;
    } else {
      std::vector<Eigen::Vector2d> flat;
      for (const auto& p : standing) flat.emplace_back(p.x(), p.y());
      x = triangulate(flat, b).position;
    }
    xs.push_back(x);
    mean += x;
  }
  mean /= n;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(dims, dims);
  for (const auto& x : xs) cov += (x - mean) * (x - mean).transpose();
  return cov / (n - 1);
}

}  // namespace

TEST(Triangulation, MatchesThePapersEquationsOnTheirSymmetricCase) {
  // Robots 1 and 2 measure theta1 and theta2, the angles between the other standing robot and
  // robot 3 (Fig. 2). Eqs. 1-2 hold with robot 1 at (-d, 0) and robot 2 at (d, 0) (the text
  // says (d, 0) and (-d, 0): with that order eq. 1 gives -x). World bearings: theta1 from
  // robot 1, pi - theta2 from robot 2.
  const double d = 1.0;
  for (double t1 : {0.3, 0.7, 1.0, 1.3}) {
    for (double t2 : {0.4, 0.785, 1.2}) {
      const double x = d * (-std::tan(t1) + std::tan(t2)) / (std::tan(t1) + std::tan(t2));  // eq. 1
      const double y = 2 * d * std::tan(t1) * std::tan(t2) / (std::tan(t1) + std::tan(t2));  // eq. 2
      TriangulationParams p;
      p.bearing_sigma = 0.01;
      const Triangulation r = triangulate({{-d, 0}, {d, 0}}, {t1, kPi - t2}, p);
      EXPECT_NEAR(r.position[0], x, 1e-9);
      EXPECT_NEAR(r.position[1], y, 1e-9);
      // eqs. 3-4 as Jacobian columns (eq. 3 with its first term's sign corrected: as printed,
      // dx = d (sin 2th2 dth1 + ...) contradicts the derivative of eq. 1)
      const double s2 = std::pow(std::sin(t1 + t2), 2);
      Eigen::Matrix2d jac;
      jac << -d * std::sin(2 * t2) / s2, d * std::sin(2 * t1) / s2,  //
          2 * d * std::pow(std::sin(t2), 2) / s2, 2 * d * std::pow(std::sin(t1), 2) / s2;
      const Eigen::Matrix2d paper = p.bearing_sigma * p.bearing_sigma * jac * jac.transpose();
      EXPECT_LT((r.covariance - paper).norm(), 1e-9 * paper.norm()) << t1 << " " << t2;
    }
  }
}

TEST(Triangulation, CovarianceMatchesMonteCarloOnRandomGeometry) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  const double sigma = 0.5 * kPi / 180.0;
  int tried = 0;
  for (int trial = 0; tried < 6 && trial < 100; ++trial) {
    const int n = 2 + trial % 3;
    std::vector<Eigen::Vector3d> standing;
    for (int i = 0; i < n; ++i) standing.emplace_back(u(gen), u(gen), 0.3 * u(gen));
    const Eigen::Vector3d target(u(gen), u(gen), 0.3 * u(gen));
    for (const bool three_d : {false, true}) {
      TriangulationParams p;
      p.bearing_sigma = sigma;
      Triangulation r;
      try {
        if (three_d) {
          std::vector<double> b, e;
          for (const auto& s : standing) {
            const Eigen::Vector3d d = target - s;
            b.push_back(std::atan2(d.y(), d.x()));
            e.push_back(std::atan2(d.z(), d.head<2>().norm()));
          }
          r = triangulate(standing, b, e, p);
        } else {
          std::vector<Eigen::Vector2d> flat;
          std::vector<double> b;
          for (const auto& s : standing) {
            flat.emplace_back(s.x(), s.y());
            b.push_back(bearing_to(flat.back(), target.head<2>()));
          }
          r = triangulate(flat, b, p);
        }
      } catch (const std::invalid_argument&) {
        continue;  // a degenerate draw: covered by the bad-input test
      }
      if (r.intersection_angle < 0.3) continue;  // first order holds for well-conditioned geometry
      ++tried;
      EXPECT_LT((r.position - (three_d ? target : Eigen::Vector3d(target.x(), target.y(), 0)).head(three_d ? 3 : 2))
                    .norm(),
                1e-9);
      const Eigen::MatrixXd mc = monte_carlo(standing, target, three_d, sigma, 20000, 100 + trial);
      EXPECT_LT((mc - r.covariance).norm(), 0.05 * r.covariance.norm()) << "trial " << trial << " 3d " << three_d;
    }
  }
  EXPECT_GE(tried, 6);
}

TEST(Triangulation, LeastSquaresUsesEveryRobot) {
  // Four robots around the target: the covariance shrinks against any two of them.
  const Eigen::Vector2d target(0.5, 2.0);
  const std::vector<Eigen::Vector2d> all = {{-2, 0}, {2, 0}, {-2, 4}, {2, 4}};
  std::vector<double> b;
  for (const auto& s : all) b.push_back(bearing_to(s, target));
  TriangulationParams p;
  p.bearing_sigma = 0.002;
  const Triangulation four = triangulate(all, b, p);
  const Triangulation two = triangulate({all[0], all[1]}, {b[0], b[1]}, p);
  EXPECT_LT((four.position - target).norm(), 1e-9);
  EXPECT_LT(four.covariance.trace(), 0.6 * two.covariance.trace());
}

TEST(Triangulation, BadGeometryAndInputAreRefusedByName) {
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { triangulate({{0, 0}}, {0.5}); }).find("at least two"), std::string::npos);
  EXPECT_NE(message([] { triangulate({{0, 0}, {0, 0}}, {0.5, 1.0}); }).find("coincide"), std::string::npos);
  EXPECT_NE(message([] { triangulate({{0, 0}, {1, 0}}, {0.5, NAN}); }).find("bearing 1 is not finite"),
            std::string::npos);
  EXPECT_NE(message([] { triangulate({{0, 0}, {1, 0}}, {0.5}); }).find("2 standing robots but 1"), std::string::npos);
  // theta1 + theta2 near 0 (the target far away along the baseline's normal: parallel rays) and
  // near pi (the target on the baseline: both rays along it)
  EXPECT_NE(message([] { triangulate({{1, 0}, {-1, 0}}, {kPi / 2 + 0.001, kPi / 2 - 0.001}); }).find("nearly parallel"),
            std::string::npos);
  EXPECT_NE(message([] { triangulate({{1, 0}, {-1, 0}}, {kPi, 0.0}); }).find("nearly parallel"), std::string::npos);
  EXPECT_NE(message([] { triangulate({{1, 0}, {-1, 0}}, {-kPi / 4, -3 * kPi / 4}); }).find("points away"),
            std::string::npos);
  const std::vector<Eigen::Vector3d> up = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_NE(message([&] { triangulate(up, {0.5, 2.0}, {kPi / 2, 0.0}); }).find("elevation 0"), std::string::npos);
  TriangulationParams bad;
  bad.bearing_sigma = -1;
  EXPECT_NE(message([&] { triangulate({{1, 0}, {-1, 0}}, {2.0, 1.0}, bad); }).find("bearing_sigma"), std::string::npos);
}

TEST(Triangulation, PairsMatchOneByOneAndNameTheBadRow) {
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Eigen::Vector2d> a, b;
  std::vector<double> ba, bb;
  for (int k = 0; k < 50; ++k) {
    a.emplace_back(u(gen) - 5.0, u(gen));
    b.emplace_back(u(gen) + 5.0, u(gen));
    const Eigen::Vector2d target(u(gen), u(gen) + 6.0);
    ba.push_back(bearing_to(a.back(), target));
    bb.push_back(bearing_to(b.back(), target));
  }
  const auto out = triangulate_pairs(a, b, ba, bb);
  for (int k = 0; k < 50; ++k) {
    const Triangulation one = triangulate({a[k], b[k]}, {ba[k], bb[k]});
    EXPECT_NEAR((out[k] - one.position).norm(), 0.0, 1e-12);
  }
  bb[17] = ba[17];  // parallel lines of sight in row 17
  try {
    triangulate_pairs(a, b, ba, bb);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 17: "), std::string::npos) << e.what();
  }
  EXPECT_THROW(triangulate_pairs(a, b, ba, {1.0}), std::invalid_argument);
}
