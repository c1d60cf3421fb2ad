#include "harness/systems/boundary/boundary_figures.h"

#include <cmath>
#include <optional>
#include <system_error>

namespace rig::harness {

namespace {

// Seed 001's vision: the cover each ROI truly had and what the controller
// measured, as two maps of the ROI centres side by side.
std::optional<Panel> vision_map_panel(const std::vector<VisionRoiSample>& rois, bool measured) {
    std::vector<std::vector<double>> data;
    Extent east, north;
    for (const VisionRoiSample& roi : rois) {
        const double value = measured ? roi.measured_pct : roi.true_pct;
        east.include(roi.east_m);
        north.include(roi.north_m);
        if (std::isfinite(value)) data.push_back({roi.east_m, roi.north_m, value});
    }
    if (east.empty()) return std::nullopt;
    Panel panel;
    panel.caption = measured ? "Cover D per ROI as the controller measured it" : "Cover D per ROI, truth";
    panel.width = 420;
    panel.height = 520;
    std::string& script = panel.script;
    script += data_block("rois", data);
    script += "set title " + gnuplot_string(measured ? "measured (controller)" : "true (crop map)") + "\n";
    script += "set xlabel " + gnuplot_string("east (m)") + "\nset ylabel " + gnuplot_string("north (m)") + "\n";
    script += "set xrange " + east.range(0.1, 0.1) + "\nset yrange " + north.range(0.02, 0.02) + "\n";
    script += "set cbrange [0:80]\nset cblabel " + gnuplot_string("cover D (%)") + "\n";
    script += "set palette defined (0 '#8c6d46', 40 '#e8d36a', 80 '#1f7a2e')\nunset key\n";
    script += data.empty() ? "plot NaN notitle\n" : "plot $rois using 1:2:3 with points pt 5 ps 0.9 lc palette notitle\n";
    return panel;
}

std::string vision_figure(FigurePage& page, const FigureContext& where, const CaseResult& result,
                          const BoundaryFigures& figures) {
    if (figures.rois.empty() && figures.frames.empty()) return {};
    std::string figure = "<figure class=\"figure vision\" id=\"" + where.anchor + "-vision\">\n";
    if (!figures.frames.empty()) {
        figure += "<div class=\"frames\">\n";
        for (const VisionFrameImage& frame : figures.frames) {
            std::filesystem::path link = frame.file;
            if (!where.report_dir.empty()) {
                std::error_code ignored;
                const std::filesystem::path relative = std::filesystem::relative(
                    std::filesystem::absolute(frame.file, ignored), std::filesystem::absolute(where.report_dir, ignored), ignored);
                if (!relative.empty()) link = relative;
            }
            std::string densities;
            for (const VisionRoiSample& roi : frame.rois) {
                densities += " nozzle " + std::to_string(roi.nozzle) + ": true " + shown_number(roi.true_pct, 3) +
                             " %, measured " +
                             (std::isfinite(roi.measured_pct) ? shown_number(roi.measured_pct, 3) + " %" : std::string("none")) + ";";
            }
            figure += "<figure class=\"frame\"><img src=\"" + html(link.generic_string()) +
                      "\" width=\"640\" alt=\"" + html((frame.camera == 0 ? "left" : "right") + std::string(" camera frame ") +
                                                      std::to_string(frame.frame_number)) +
                      "\"><figcaption>" + (frame.camera == 0 ? "Left" : "Right") + " camera, frame " +
                      std::to_string(frame.frame_number) + ":" + html(densities) + "</figcaption></figure>\n";
        }
        figure += "</div>\n";
    }
    figure += "<div class=\"panels\">\n";
    for (const bool measured : {false, true}) {
        if (std::optional<Panel> map = vision_map_panel(figures.rois, measured)) {
            map->what = where.label + (measured ? ": measured cover map" : ": true cover map");
            figure += page.place(std::move(*map));
        }
    }
    figure += "</div>\n<figcaption>Seed 001's vision: each camera's frame from the middle of the run with every "
              "nozzle's Sec. 2.1 ROI (600 x 400 mm, 200-600 mm ahead of the nozzle) outlined where it truly lies; "
              "below, the cover D of every ROI of every frame at its centre, from the crop truth and as the "
              "controller measured it (Eq. 15-17). A ROI without a measurement is left out of the second map.";
    if (const std::optional<double> error = finite_metric(result, "vision_worst_camera_density_error_mean_abs_pct")) {
        figure += " Worst camera's mean |error| " + shown_number(*error, 3) + " points of cover.";
    }
    return figure + "</figcaption>\n</figure>\n";
}

}  // namespace

std::string BoundaryFigures::html(FigurePage& page, const FigureContext& where, const CaseResult& result) const {
    return vision_figure(page, where, result, *this);
}

}  // namespace rig::harness
