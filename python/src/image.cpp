// Images, comparison and convergence studies from Python: write_image / read_image, the EXR
// with variances and counts (write_render_exr / read_render), compare() and converge().
#include <cmath>

#include "common.hpp"
#include "core/file_io.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/parts.hpp"
#include "scene/validate.hpp"

namespace lucent::python {

namespace {

py::tuple triple(const double v[3]) { return py::make_tuple(v[0], v[1], v[2]); }

/// Sample ranges as a list of (begin, end) tuples, [begin, end).
py::list range_list(const std::vector<SampleRange>& ranges) {
  py::list out;
  for (const SampleRange& r : ranges) out.append(py::make_tuple(r.begin, r.end));
  return out;
}

/// What merge_parts gives Python: the merged image and what the parts held.
struct MergedParts {
  RenderResult result;
  PartInfo info;
  std::vector<SampleRange> missing;
  std::uint32_t min_spp = 0, max_spp = 0;
  double mean_spp = 0;
};

/// The display settings of `film` (a Film or None: the defaults), each overridden when given.
DisplaySettings display_settings(const Film* film, py::object transfer, py::object gamma,
                                 py::object exposure, py::object tonemap) {
  DisplaySettings d;
  if (film) d = DisplaySettings{film->transfer, film->gamma, film->exposure, film->tonemap};
  auto text = [](py::handle v, const char* what) {
    if (!py::isinstance<py::str>(v))
      throw py::type_error(std::string(what) + ": expected a string, got " +
                           py::repr(v).cast<std::string>());
    return v.cast<std::string>();
  };
  auto number = [](py::handle v, const char* what) {
    if (py::isinstance<py::bool_>(v) || py::isinstance<py::str>(v) || !py::hasattr(v, "__float__"))
      throw py::type_error(std::string(what) + ": expected a number, got " +
                           py::repr(v).cast<std::string>());
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  };
  if (!transfer.is_none()) d.transfer = parse_enum<Transfer>(text(transfer, "transfer"));
  if (!tonemap.is_none()) d.tonemap = parse_enum<ToneMap>(text(tonemap, "tonemap"));
  if (!gamma.is_none()) d.gamma = number(gamma, "gamma");
  if (!exposure.is_none()) d.exposure = number(exposure, "exposure");
  if (!(d.gamma > 0) || !std::isfinite(d.gamma))
    throw py::value_error("gamma must be a finite number > 0, got " +
                          py::repr(py::float_(d.gamma)).cast<std::string>());
  if (!std::isfinite(d.exposure)) throw py::value_error("exposure must be finite");
  // as a scene file's film refuses it: a gamma shapes the "gamma" transfer only (it was dropped
  // without a word with srgb or linear)
  if (!gamma.is_none() && d.transfer != Transfer::Gamma)
    throw py::value_error(std::string("gamma: only used with transfer 'gamma' (the transfer is ") +
                          (d.transfer == Transfer::Srgb ? "srgb" : "linear") + ")");
  return d;
}

}  // namespace

void bind_image(py::module_& m) {
  m.def(
      "write_image",
      [](const std::filesystem::path& path, py::handle image, const Film* film, py::object transfer,
         py::object gamma, py::object exposure, py::object tonemap) {
        std::string p = path.string();
        // display settings given for a linear file change nothing: refused, as the CLI refuses
        // options that change nothing (they were dropped without a word)
        const std::string ext = io::lower_extension(p);
        if (ext == ".exr" || ext == ".pfm")
          for (const auto& [given, name] : {std::pair{&transfer, "transfer"},
                                            {&gamma, "gamma"},
                                            {&exposure, "exposure"},
                                            {&tonemap, "tonemap"}})
            if (!given->is_none())
              throw py::value_error(std::string("write_image: ") + name +
                                    " is a display setting, "
                                    "for .png; " +
                                    ext + " holds linear values");
        DisplaySettings d = display_settings(film, transfer, gamma, exposure, tonemap);
        RenderResult r = render_result_from(image, "image");
        ReleaseGil release;
        write_image(p, r.mean, d);
      },
      py::arg("path"), py::arg("image"), py::kw_only(), py::arg("film") = nullptr,
      py::arg("transfer") = py::none(), py::arg("gamma") = py::none(),
      py::arg("exposure") = py::none(), py::arg("tonemap") = py::none(),
      "Writes an (H, W, 3) array or a RenderResult's mean: .png (8-bit, display-encoded with "
      "the film's settings, or the defaults, each overridable), .pfm or .exr (linear float).");
  m.def(
      "read_image",
      [](const std::filesystem::path& path) {
        Image img;
        std::string p = path.string();
        {
          ReleaseGil release;
          img = read_image(p);
        }
        return image_array(std::move(img));
      },
      py::arg("path"),
      "Reads .pfm, .exr (linear) or an 8-bit image (decoded to linear) as an (H, W, 3) float32 "
      "array; a lucent part file gives the image of its checksummed sums (a damaged one "
      "raises).");
  m.def(
      "write_render_exr",
      [](const std::filesystem::path& path, py::handle result) {
        RenderResult r = render_result_from(result, "result");
        std::string p = path.string();
        // OpenEXR whatever the name said (w.png was an EXR); as converge's save_reference
        if (io::lower_extension(p) != ".exr")
          throw Error(p + ": write_render_exr writes OpenEXR: use an .exr file");
        ReleaseGil release;
        write_render_exr(p, r);
      },
      py::arg("path"), py::arg("result"),
      "Writes an OpenEXR with the mean (R, G, B) and, when the result has them, the variances "
      "(var.R, var.G, var.B) and sample counts (n) that compare() uses.");
  m.def(
      "read_render",
      [](const std::filesystem::path& path) {
        std::string p = path.string();
        ReleaseGil release;
        return read_render(p);
      },
      py::arg("path"),
      "Reads an image as a RenderResult: an EXR with variances and counts, or any image "
      "read_image() reads (variance and samples None).");

  py::class_<PartInfo>(m, "PartInfo", "A part file's header (docs/parts.md).")
      .def_readonly("width", &PartInfo::width)
      .def_readonly("height", &PartInfo::height)
      .def_readonly("scene_hash", &PartInfo::scene_hash,
                    "the hash of what makes the image (scene, camera, film, integrator, ...)")
      .def_readonly("seed", &PartInfo::seed)
      .def_readonly("sampler", &PartInfo::sampler)
      .def_readonly("integrator", &PartInfo::integrator)
      .def_readonly("version", &PartInfo::version, "lucent's version that rendered it")
      .def_property_readonly(
          "scene", [](const PartInfo& i) { return FileText{i.scene}; },
          "the scene file (informative)")
      .def_property_readonly(
          "samples", [](const PartInfo& i) { return range_list(i.samples); },
          "the sample ranges rendered: a list of (begin, end), [begin, end)")
      .def_property_readonly(
          "requested", [](const PartInfo& i) { return range_list(i.requested); },
          "the sample ranges asked for")
      .def_readonly("nonfinite", &PartInfo::nonfinite)
      .def_readonly("rays", &PartInfo::rays)
      .def_readonly("seconds", &PartInfo::seconds, "kernel seconds, summed over merged parts")
      .def("__repr__", [](const PartInfo& i) {
        return "<lucent.PartInfo " + std::to_string(i.width) + "x" + std::to_string(i.height) +
               ", samples " + ranges_text(i.samples) + ">";
      });
  m.def(
      "read_part_info",
      [](const std::filesystem::path& path) {
        std::string p = path.string();
        ReleaseGil release;
        return read_part_info(p);
      },
      py::arg("path"), "Reads a part file's header (its pixels are not read).");

  py::class_<MergedParts>(m, "MergedParts", "What merge_parts() made.")
      .def_readonly("result", &MergedParts::result,
                    "the merged image (a RenderResult: mean, variance, samples, ...)")
      .def_readonly("info", &MergedParts::info, "its header (a PartInfo)")
      .def_property_readonly(
          "missing", [](const MergedParts& m) { return range_list(m.missing); },
          "the sample ranges the parts do not hold, of `expect` (or of [0, the highest end a "
          "part asked for))")
      .def_readonly("min_spp", &MergedParts::min_spp, "finite samples per pixel, the fewest")
      .def_readonly("mean_spp", &MergedParts::mean_spp)
      .def_readonly("max_spp", &MergedParts::max_spp)
      .def("__repr__", [](const MergedParts& m) {
        return "<lucent.MergedParts " + std::to_string(m.info.width) + "x" +
               std::to_string(m.info.height) + ", samples " + ranges_text(m.info.samples) +
               (m.missing.empty() ? "" : ", missing " + ranges_text(m.missing)) + ">";
      });
  m.def(
      "merge_parts",
      [](const std::vector<std::filesystem::path>& paths,
         std::optional<std::filesystem::path> output, py::object expect,
         const FlagArg& complete_arg) {
        const bool complete = flag_argument(complete_arg, "complete");
        std::vector<std::string> inputs;
        for (const auto& p : paths) inputs.push_back(p.string());
        if (inputs.empty()) throw py::value_error("merge_parts: no part files given");
        const std::string out = output ? output->string() : std::string();
        // what the parts hold together (many parts of at most 2**24 samples each)
        std::optional<SampleRange> want;
        if (!expect.is_none()) want = range_argument(expect, "expect", std::uint64_t(1) << 32);
        MergeReport r;
        {
          ReleaseGil release;
          // as `lucent merge`: the output checked before any part is read
          if (!out.empty()) check_merge_output(out, inputs);
          r = merge_render_parts(inputs);
          check_merge_coverage(r, want, complete, "expect", "complete");
          if (!out.empty()) write_merged(out, r.merged);
        }
        // as `lucent merge` says it (a script's output= was an image of fewer samples without a
        // word; `missing` said it only to a caller who looked)
        if (!r.missing.empty())
          py::module_::import("warnings")
              .attr("warn")(
                  "samples " + ranges_text(r.missing) + " are missing: the image has fewer samples",
                  py::module_::import("lucent").attr("LucentWarning"), 1);
        MergedParts m;
        m.result = part_result(r.merged);
        m.info = r.merged.info;
        m.missing = r.missing;
        m.min_spp = r.min_spp;
        m.max_spp = r.max_spp;
        m.mean_spp = r.mean_spp;
        return m;
      },
      py::arg("paths"), py::kw_only(), py::arg("output") = py::none(),
      py::arg("expect") = py::none(), py::arg("complete") = false,
      "Merges part files (Renderer.write_part, `lucent render --samples A:B`) into the image of "
      "their samples, exactly as `lucent merge` does: they must be of one image (film, seed, "
      "integrator, scene hash) with disjoint ranges, added in ascending order of their first "
      "sample whatever order they are given in. output: also writes it (.exr: a part file, "
      "mergeable again; .png; .pfm). expect=(begin, end): the samples the parts should hold "
      "together; complete=True raises when some are missing.");

  py::class_<CompareResult>(m, "CompareResult",
                            "The per-pixel z-test of two images (docs/compare.md).")
      .def_readonly("width", &CompareResult::width)
      .def_readonly("height", &CompareResult::height)
      .def_readonly("passed", &CompareResult::passed)
      .def_readonly("statistical", &CompareResult::statistical)
      .def_readonly("z_threshold", &CompareResult::z_threshold)
      .def_readonly("tested", &CompareResult::tested)
      .def_readonly("failed_channels", &CompareResult::failed_channels)
      .def_readonly("failed_pixels", &CompareResult::failed_pixels)
      .def_readonly("pass_fraction", &CompareResult::pass_fraction)
      .def_readonly("required_fraction", &CompareResult::required_fraction)
      .def_readonly("max_z", &CompareResult::max_z)
      .def_readonly("max_z_x", &CompareResult::max_z_x)
      .def_readonly("max_z_y", &CompareResult::max_z_y)
      .def_readonly("max_z_channel", &CompareResult::max_z_channel)
      .def_property_readonly("mean_a", [](const CompareResult& c) { return triple(c.mean_a); })
      .def_property_readonly("mean_b", [](const CompareResult& c) { return triple(c.mean_b); })
      .def_property_readonly("mean_z", [](const CompareResult& c) { return triple(c.mean_z); })
      .def_readonly("mean_z_threshold", &CompareResult::mean_z_threshold)
      .def_readonly("mean_test_passed", &CompareResult::mean_test_passed)
      .def_readonly("light_paths_a", &CompareResult::light_paths_a,
                    "the image-mean test took A's light-traced part (caustics) from its light "
                    "paths' totals (RenderResult.light_mean_variance), not from its pixels")
      .def_readonly("light_paths_b", &CompareResult::light_paths_b)
      .def_readonly("mean_variance_share", &CompareResult::mean_variance_share,
                    "the largest share one pixel-channel holds of the image means' variance "
                    "(see mean_variance_samples)")
      .def_readonly("mean_variance_x", &CompareResult::mean_variance_x)
      .def_readonly("mean_variance_y", &CompareResult::mean_variance_y)
      .def_readonly("mean_variance_channel", &CompareResult::mean_variance_channel)
      .def_readonly("mean_variance_samples", &CompareResult::mean_variance_samples,
                    "the samples that pixel's mean rests on, in the image holding most of its "
                    "variance: mean^2 n / var, or the excess over the other image's mean in "
                    "place of the mean where the other image has under a tenth of its variance "
                    "per sample; infinite for a mean of 0 or below")
      .def_property_readonly(
          "mean_variance_dominated", &CompareResult::mean_variance_dominated,
          "mean_variance_share > 0.5 and mean_variance_samples < 10: one rare, bright value "
          "decides the image-mean test, and the summary warns (docs/compare.md)")
      .def_readonly("few_sample_pixels", &CompareResult::few_sample_pixels,
                    "pixels resting on fewer than 8 samples in an image carrying variances: "
                    "their sample variances are unreliable, and the summary warns")
      .def_readonly("zero_variance_failures", &CompareResult::zero_variance_failures,
                    "failing pixel-channels where only one image carries variances and its pixel "
                    "has none from fewer than 64 samples: the summary warns")
      .def_readonly("rmse", &CompareResult::rmse)
      .def_readonly("relmse", &CompareResult::relmse)
      .def_readonly("max_abs_error", &CompareResult::max_abs_error)
      .def_property_readonly(
          "z",
          [](py::object self) {
            const CompareResult& c = self.cast<const CompareResult&>();
            return view(c.z.rgb, {c.z.height, c.z.width, 3}, self);
          },
          "(H, W, 3) float32: signed z of each pixel-channel (a view)")
      .def("summary", &CompareResult::summary, "The report `lucent compare` prints.")
      .def("__bool__", [](const CompareResult& c) { return c.passed; })
      .def("__repr__", [](const CompareResult& c) {
        return std::string("<lucent.CompareResult ") + (c.passed ? "passed" : "FAILED") +
               ", max |z| " + std::to_string(c.max_z) + ", RMSE " + std::to_string(c.rmse) + ">";
      });

  m.def(
      "compare",
      [](py::handle a, py::handle b, double alpha, double min_pass_fraction, double abs_epsilon,
         double rel_epsilon, const FlagArg& image_mean_test_arg) {
        const bool image_mean_test = flag_argument(image_mean_test_arg, "image_mean_test");
        // the library's and the command line's range (0.7 passed here, then failed there), the
        // value as it reads back (std::to_string said "got 0.000000" of 1e-13)
        if (!(alpha >= 1e-12 && alpha <= 0.5))
          throw py::value_error("alpha must be in [1e-12, 0.5], got " +
                                scene_detail::format_number(alpha));
        if (!(min_pass_fraction >= 0 && min_pass_fraction <= 1))
          throw py::value_error("min_pass_fraction must be in [0, 1], got " +
                                scene_detail::format_number(min_pass_fraction));
        if (!(abs_epsilon >= 0) || !(rel_epsilon >= 0) || !std::isfinite(abs_epsilon) ||
            !std::isfinite(rel_epsilon))
          throw py::value_error("abs_epsilon and rel_epsilon must be finite and >= 0");
        RenderResult ra = render_result_from(a, "a"), rb = render_result_from(b, "b");
        check_comparable_image(ra, "a");  // as `lucent compare`: an input error, not a FAIL
        check_comparable_image(rb, "b");
        CompareOptions o;
        o.alpha = alpha;
        o.min_pass_fraction = min_pass_fraction;
        o.abs_epsilon = abs_epsilon;
        o.rel_epsilon = rel_epsilon;
        o.image_mean_test = image_mean_test;
        ReleaseGil release;
        return compare_images(ra, rb, o);
      },
      py::arg("a"), py::arg("b"), py::kw_only(), py::arg("alpha") = CompareOptions{}.alpha,
      py::arg("min_pass_fraction") = CompareOptions{}.min_pass_fraction,
      py::arg("abs_epsilon") = CompareOptions{}.abs_epsilon,
      py::arg("rel_epsilon") = CompareOptions{}.rel_epsilon,
      py::arg("image_mean_test") = CompareOptions{}.image_mean_test,
      "Per-pixel z-test of two RenderResults (or (H, W, 3) arrays: no variance), as `lucent "
      "compare`.");
}

}  // namespace lucent::python
