// imufit — a run's time stamps placed, as they come, on a uniform grid t_k = a + b k, so that a
// stamp's slot says how many samples were lost before it (windows.h: lost samples and turns).
//
// The line through the stamps placed so far (least squares, weighted towards the last kMemory
// samples so that a drifting clock is followed) says which slot a stamp is nearest to; a jump of
// more than one slot is a gap, and jitter of less than half an interval moves no slot.
#ifndef IMUFIT_RUN_SAMPLE_CLOCK_H_
#define IMUFIT_RUN_SAMPLE_CLOCK_H_

#include <vector>

namespace imufit {

// Places time stamps, in order, on a uniform grid t_k = a + b k (see above).
//
// Acquisition: the first kAcquire stamps are taken provisionally as consecutive slots; then the
// grid is found from them at once: b is the interval that lines their phases 2 pi t / b up best
// (the largest resultant |sum exp(2 pi i t / b)|, searched around the median interval), a the
// phase of that resultant. Lost samples leave a phase unchanged and jitter only blurs it, so one
// lost sample among the first stamps cannot tilt the grid (a line fitted to stamps taken as
// consecutive would be). When the resultant is too weak (no grid: bunched stamps) every stamp
// stays one slot after the one before.
// Tracking: the line is an exponentially weighted least-squares fit over the stamps placed (a
// memory of about kMemory samples, so a drifting clock is followed); each stamp goes to the slot
// nearest to it on that line. kRelock stamps in a row off the grid (the clock jumped), or
// 4 kAcquire without a grid, start a new acquisition. Lost samples among the stamps of an
// acquisition go uncounted.
class SampleClock {
 public:
  static constexpr double kMemory = 20000.0;
  static constexpr int kAcquire = 256;
  // A stamp farther from its slot than this many intervals is off the grid.
  static constexpr double kTolerance = 0.45;
  static constexpr int kRelock = 32;

  // Places the next stamp; returns the slots it lies after the stamp before: 1, or more after lost
  // samples (always 1 while a grid is acquired).
  long long Place(double time_s);
  // Whether the stamp just placed lay within kTolerance intervals of its slot (judged once a grid
  // is locked; stamps on no grid are all off it).
  bool on_grid() const { return on_grid_; }
  // The grid's interval b, s (0 before two stamps).
  double interval_s() const { return slot_variance_ > 0.0 ? covariance_ / slot_variance_ : 0.0; }

 private:
  void Acquire();
  void Update(double slot, double time_s);
  void ResetLine();

  std::vector<double> acquiring_;  // stamps since the last (re)acquisition began
  bool acquired_ = false;
  bool locked_ = false;  // a grid was found at the last acquisition
  double slot_ = -1.0;
  bool on_grid_ = true;
  int off_grid_run_ = 0;
  // Exponentially weighted means of slot and time and co-moments (Welford's update with decay).
  double weight_ = 0.0, mean_slot_ = 0.0, mean_time_s_ = 0.0, slot_variance_ = 0.0, covariance_ = 0.0;
};

}  // namespace imufit

#endif  // IMUFIT_RUN_SAMPLE_CLOCK_H_
