// Benchmark tdbem_scaling (bench.hpp): TD-BEM CPU time against the number of steps.
#include <fmt/format.h>

#include "core/io/plot.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/metrics.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"

namespace backbone::contact_bar {

int bench_tdbem_scaling(const std::filesystem::path& out) {
  fmt::print(
      "bench tdbem_scaling: TD-BEM (event contact) on mode 1 over 10 periods, "
      "history_samples = 2, energy off\n");
  const bench::PaperMode1 mode1 = bench::paper_mode1();
  const TdbemSolver tdbem(ContactMethod::event);
  const double t_end = 10 * mode1.episode.period;
  core::Table table({"steps", "seconds", "seconds_per_step"});
  std::vector<double> steps, seconds;
  for (double n : {1e3, 1e4, 1e5, 1e6}) {
    bar::SimulationOptions o;
    o.t_end = t_end;
    o.dt = t_end / n;
    o.history_samples = 2;
    o.energy = false;
    bool ok = true;
    const double s = bench::best_seconds(
        [&] { ok = ok && tdbem.simulate(mode1.setup, o).t.size() == 2; }, n >= 1e6 ? 0.0 : 1e9);
    if (!ok) fmt::print("  warning: march stopped early at n = {:g}\n", n);
    steps.push_back(n);
    seconds.push_back(s);
    table.add_row({n, s, s / n});
  }
  const double slope = log_log_slope(steps, seconds);
  const std::filesystem::path csv = out / "tdbem_scaling.csv";
  table.write_csv(csv);
  core::Table fit({"slope"});
  fit.add_row({slope});
  fit.write_csv(out / "tdbem_scaling_fit.csv");
  fmt::print("{}", table.aligned());
  fmt::print("  fitted slope of log(seconds) vs log(steps): {:.3f} (1 = linear cost)\n", slope);
  bench::plot(out / "tdbem_scaling.png",
              fmt::format("set logscale xy\nset grid\nset xlabel 'time steps n'\n"
                          "set ylabel 'CPU seconds'\nset title 'TD-BEM march cost, fitted "
                          "slope {:.3f}'\nset key left top\n"
                          "plot {} using 1:2 with linespoints pt 7 title 'TD-BEM (event)', "
                          "{:.6g}*x title 'linear (through n = 1e6)' dt 2\n",
                          slope, core::gnuplot_quote(csv), seconds.back() / steps.back()));
  return 0;
}

}  // namespace backbone::contact_bar
