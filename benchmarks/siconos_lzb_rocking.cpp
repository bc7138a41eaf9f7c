// Free rocking of a rectangular block under Siconos's LZB multiple-impact law
// (MultipleImpactNSL, the MultipleImpact one-step problem, LsodarOSI, EventDriven).
//
// A probe for benchmarks/bench_siconos_mu.py: Siconos 4.4's Python wrapper has the law
// (siconos.kernel.MultipleImpactNSL) but not its one-step problem, so it runs in C++.
// The MultipleImpact problem acts on the normal components only: the corners slide without
// friction (Housner's rocking needs them to stick).
//
// usage: siconos_lzb_rocking half_width_m half_height_m theta0_rad e K_left K_right eta dP t_end
// prints  I t omega_minus omega_plus vy_plus   at each impact, and
//         S t theta omega                       at every other event (1 ms grid).
// the headers of the classes used, not SiconosKernel.hpp (which took 2 s more of compiling)
#include "BlockVector.hpp"
#include "Event.hpp"
#include "EventDriven.hpp"
#include "EventsManager.hpp"
#include "Interaction.hpp"
#include "LCP.hpp"
#include "LagrangianLinearTIDS.hpp"
#include "LagrangianScleronomousR.hpp"
#include "LsodarOSI.hpp"
#include "MultipleImpact.hpp"
#include "MultipleImpactNSL.hpp"
#include "NonSmoothDynamicalSystem.hpp"
#include "SiconosVector.hpp"
#include "SimpleMatrix.hpp"
#include "TimeDiscretisation.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

// One base corner: gap y = q_y + s b sin(theta) - h cos(theta), s = -1 left, +1 right.
class CornerR : public LagrangianScleronomousR {
 public:
  CornerR(double b, double h, double s) : LagrangianScleronomousR(), b_(b), h_(h), s_(s) {}
  void computeh(const BlockVector& q, BlockVector&, SiconosVector& y) override {
    const double th = q.getValue(2);
    y.setValue(0, q.getValue(1) + s_ * b_ * std::sin(th) - h_ * std::cos(th));
  }
  void computeJachq(const BlockVector& q, BlockVector&) override {
    const double th = q.getValue(2);
    _jachq->setValue(0, 0, 0.0);
    _jachq->setValue(0, 1, 1.0);
    _jachq->setValue(0, 2, s_ * b_ * std::cos(th) + h_ * std::sin(th));
  }
  void computeDotJachq(const BlockVector& q, BlockVector&, const BlockVector& qdot) override {
    const double th = q.getValue(2), w = qdot.getValue(2);
    _dotjachq->setValue(0, 0, 0.0);
    _dotjachq->setValue(0, 1, 0.0);
    _dotjachq->setValue(0, 2, (-s_ * b_ * std::sin(th) + h_ * std::cos(th)) * w);
  }

 private:
  double b_, h_, s_;
};

int main(int argc, char* argv[]) {
  if (argc != 10) {
    std::fprintf(stderr, "usage: %s b h theta0 e K_left K_right eta dP t_end\n", argv[0]);
    return 2;
  }
  const double b = std::atof(argv[1]), h = std::atof(argv[2]), theta0 = std::atof(argv[3]);
  const double e = std::atof(argv[4]), k_left = std::atof(argv[5]), k_right = std::atof(argv[6]);
  const double eta = std::atof(argv[7]), dp = std::atof(argv[8]), t_end = std::atof(argv[9]);
  const double m = 1.0, g = 9.81, inertia = m * (b * b + h * h) / 3.0;  // solid rectangle
  try {
    SP::SiconosMatrix mass(new SimpleMatrix(3, 3));
    (*mass)(0, 0) = m;
    (*mass)(1, 1) = m;
    (*mass)(2, 2) = inertia;
    // released from rest, standing on its left corner at the origin
    SP::SiconosVector q0(new SiconosVector(3)), v0(new SiconosVector(3));
    (*q0)(0) = b * std::cos(theta0) - h * std::sin(theta0);
    (*q0)(1) = b * std::sin(theta0) + h * std::cos(theta0);
    (*q0)(2) = theta0;
    SP::LagrangianLinearTIDS block(new LagrangianLinearTIDS(q0, v0, mass));
    SP::SiconosVector weight(new SiconosVector(3));
    (*weight)(1) = -m * g;
    block->setFExtPtr(weight);
    SP::NonSmoothLaw law_left(new MultipleImpactNSL(e, k_left, eta));
    SP::NonSmoothLaw law_right(new MultipleImpactNSL(e, k_right, eta));
    SP::Relation rel_left(new CornerR(b, h, -1.0)), rel_right(new CornerR(b, h, 1.0));
    SP::Interaction left(new Interaction(law_left, rel_left)), right(new Interaction(law_right, rel_right));
    SP::NonSmoothDynamicalSystem nsds(new NonSmoothDynamicalSystem(0.0, t_end));
    nsds->insertDynamicalSystem(block);
    nsds->link(left, block);
    nsds->link(right, block);
    SP::TimeDiscretisation grid(new TimeDiscretisation(0.0, 1e-3));
    SP::LsodarOSI osi(new LsodarOSI());
    SP::MultipleImpact impact(new MultipleImpact("BiStiffness", dp));
    impact->SetSaveData(false);
    impact->SetNstepMax(10000000);
    SP::OneStepNSProblem smooth(new LCP());
    SP::EventDriven sim(new EventDriven(nsds, grid));
    sim->insertIntegrator(osi);
    sim->insertNonSmoothProblem(impact, SICONOS_OSNSP_ED_IMPACT);
    sim->insertNonSmoothProblem(smooth, SICONOS_OSNSP_ED_SMOOTH_ACC);
    SP::EventsManager events = sim->eventsManager();
    SP::SiconosVector q = block->q(), v = block->velocity();
    unsigned long n = 0;
    while (sim->hasNextEvent() && n < 2000000) {
      sim->advanceToEvent();
      const bool nonsmooth = events->nextEvent()->getType() == 2;
      const double w_minus = (*v)(2);
      sim->processEvents();
      if (nonsmooth && sim->startingTime() > 0.0) {
        std::printf("I %.9f %.9e %.9e %.9e\n", sim->startingTime(), w_minus, (*v)(2), (*v)(1));
      } else {
        std::printf("S %.9f %.9e %.9e\n", sim->startingTime(), (*q)(2), (*v)(2));
      }
      ++n;
    }
  } catch (...) {
    std::fprintf(stderr, "siconos exception\n");
    return 1;
  }
  return 0;
}
