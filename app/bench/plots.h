// The report's plots, drawn by gnuplot from data files the bench writes (OUT/plots/*.dat and
// *.gp): speed against error per scene (each point named, the Pareto front marked, error on a
// log scale), the progressive passes (time against RMSE), and the knobs (max-level, push delta,
// secondary-ray offset).
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "app/bench/bench_rows.h"

namespace lancer::bench {

enum class PlotFormat { Png, Svg };

struct Figure {
    std::string name;  ///< "speed_vs_error-balls-3"
    std::string
        file;  ///< the plot, relative to the output directory ("speed_vs_error-balls-3.svg")
    std::string title;    ///< what it shows
    std::string caption;  ///< how to read it
    bool drawn = false;
    std::string why;  ///< why it was not drawn (gnuplot missing or failed)
};

/// Write the data and scripts of every plot the rows have data for into DIR/plots/, run gnuplot
/// on each (the plot goes to DIR/NAME.png or .svg) and list them, drawn or not.
std::vector<Figure> drawPlots(const std::string& dir, const std::deque<BenchRow>& rows,
                              const std::vector<std::string>& scenes, PlotFormat format);

/// A name for files made from scene `spec`: "builtin:balls:3" -> "balls-3", "a/b/gears2.nff" ->
/// "gears2".
std::string sceneSlug(const std::string& spec);

}  // namespace lancer::bench
