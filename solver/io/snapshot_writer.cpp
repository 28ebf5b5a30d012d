#include "io/snapshot_writer.hpp"

#include <H5Cpp.h>
#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "io/hdf5_util.hpp"
#include "io/run_directory.hpp"

namespace caplab::io {

namespace fs = std::filesystem;

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string join(const std::vector<hsize_t>& dims) {
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i) {
    if (i > 0) s += ' ';
    s += std::to_string(dims[i]);
  }
  return s;
}

/// One step of the temporal collection: its time, HDF5 group and the XDMF grids it holds.
struct Step {
  double time;
  std::string group;
  std::vector<std::string> grids_xml;
  std::set<std::string> names;
};

}  // namespace

template <int D>
struct SnapshotWriter<D>::Impl {
  fs::path h5_path, xdmf_path;
  std::string href;              // XML-escaped
  std::optional<H5::H5File> h5;  // optional: H5File's copy assignment is deprecated
  std::vector<Step> steps;
  bool open = false;

  /// Throws unless `time` may be written and `name` is free in its step (no side effect).
  void check_step(double time, const std::string& name) const {
    if (!open) throw core::Error("io: snapshot file '" + h5_path.string() + "' is closed");
    if (!std::isfinite(time)) throw core::Error("io: snapshot time must be finite");
    if (!steps.empty()) {
      const Step& last = steps.back();
      if (time < last.time)
        throw core::Error(
            fmt::format("io: snapshot time {} is before the last step's time {}", time, last.time));
      if (time == last.time && last.names.count(name))
        throw core::Error("io: '" + name + "' was already written at time " + fmt::format("{}", time));
    }
  }

  /// The step for `time` (the last one, or a new one), with `name` reserved in it.
  Step& step_for(double time, const std::string& name) {
    if (steps.empty() || time > steps.back().time) {
      const std::string group = fmt::format("step_{:06d}", steps.size());
      H5::Group g = h5->createGroup(group);
      detail::write_double_attribute(g, "time", {time});
      steps.push_back(Step{time, group, {}, {}});
    }
    steps.back().names.insert(name);
    return steps.back();
  }

  std::string data_item(const std::string& path, const std::vector<hsize_t>& dims,
                        bool integer = false) const {
    return fmt::format(
        R"(<DataItem Dimensions="{}" NumberType="{}" Precision="{}" Format="HDF">{}:{}</DataItem>)",
        join(dims), integer ? "Int" : "Float", integer ? 4 : 8, href, path);
  }

  std::string attribute(const std::string& name, bool vector, const std::string& path,
                        const std::vector<hsize_t>& dims) const {
    return fmt::format(R"(          <Attribute Name="{}" AttributeType="{}" Center="Node">)"
                       "\n            {}\n          </Attribute>\n",
                       name, vector ? "Vector" : "Scalar", data_item(path, dims));
  }

  /// Flushes the HDF5 file, then rewrites the XDMF index atomically.
  void publish() {
    h5->flush(H5F_SCOPE_LOCAL);
    std::string xml =
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
        "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
        "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
        "  <Domain>\n"
        "    <Grid Name=\"snapshots\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const Step& s : steps) {
      xml += fmt::format("      <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
                         s.group);
      xml += fmt::format("        <Time Value=\"{}\"/>\n", s.time);
      for (const std::string& g : s.grids_xml) xml += g;
      xml += "      </Grid>\n";
    }
    xml +=
        "    </Grid>\n"
        "  </Domain>\n"
        "</Xdmf>\n";
    write_file_atomically(xdmf_path, xml);
  }
};

template <int D>
SnapshotWriter<D>::SnapshotWriter(fs::path h5_file, fs::path xdmf_file, std::string h5_href,
                                  const nlohmann::json& attributes)
    : impl_(std::make_unique<Impl>()) {
  static_assert(D == 2 || D == 3, "SnapshotWriter is for 2D and 3D");
  Impl& m = *impl_;
  m.h5_path = std::move(h5_file);
  m.xdmf_path = std::move(xdmf_file);
  m.href = xml_escape(h5_href.empty() ? m.h5_path.filename().string() : h5_href);
  CAPLAB_CHECK(attributes.is_null() || attributes.is_object(),
               "io: snapshot attributes must be a JSON object");
  detail::translate_h5_errors("creating the snapshot file", m.h5_path, [&] {
    m.h5.emplace(m.h5_path.string(), H5F_ACC_TRUNC);
    detail::write_json_attributes(*m.h5, attributes);
    m.h5->flush(H5F_SCOPE_LOCAL);
  });
  m.open = true;
}

template <int D>
SnapshotWriter<D> SnapshotWriter<D>::reopen(fs::path h5_file, fs::path xdmf_file, std::string h5_href,
                                            const nlohmann::json& index) {
  SnapshotWriter<D> w;
  Impl& m = *w.impl_;
  m.h5_path = std::move(h5_file);
  m.xdmf_path = std::move(xdmf_file);
  m.href = xml_escape(h5_href.empty() ? m.h5_path.filename().string() : h5_href);
  for (const auto& s : index)
    m.steps.push_back(Step{s.at("time").get<double>(), s.at("group").get<std::string>(),
                           s.at("grids_xml").get<std::vector<std::string>>(),
                           s.at("names").get<std::set<std::string>>()});
  detail::translate_h5_errors("reopening the snapshot file", m.h5_path, [&] {
    m.h5.emplace(m.h5_path.string(), H5F_ACC_RDWR);
    // Steps written after the index (by the interrupted process) are written again.
    for (std::size_t k = m.steps.size();; ++k) {
      const std::string group = fmt::format("step_{:06d}", k);
      if (!m.h5->nameExists(group)) break;
      m.h5->unlink(group);
    }
    for (const Step& s : m.steps)
      if (!m.h5->nameExists(s.group))
        throw core::Error("io: the snapshot file '" + m.h5_path.string() + "' lacks the step '" + s.group +
                          "' that the checkpoint lists");
  });
  m.open = true;
  m.publish();
  return w;
}

template <int D>
nlohmann::json SnapshotWriter<D>::index() const {
  nlohmann::json steps = nlohmann::json::array();
  for (const Step& s : impl_->steps)
    steps.push_back({{"time", s.time}, {"group", s.group}, {"grids_xml", s.grids_xml}, {"names", s.names}});
  return steps;
}

template <int D>
SnapshotWriter<D>::SnapshotWriter() : impl_(std::make_unique<Impl>()) {}

template <int D>
SnapshotWriter<D>::~SnapshotWriter() {
  if (!impl_) return;
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see the error
  }
}

template <int D>
SnapshotWriter<D>::SnapshotWriter(SnapshotWriter&&) noexcept = default;
template <int D>
SnapshotWriter<D>& SnapshotWriter<D>::operator=(SnapshotWriter&&) noexcept = default;

template <int D>
void SnapshotWriter<D>::add_grid_field_step(double time, const field::Grid<D>& grid,
                                            const std::string& block_name, const ScalarFields& scalar_fields,
                                            const GridVectorFields& vector_fields) {
  Impl& m = *impl_;
  // Validate everything before touching the file, so a rejected call leaves no trace.
  detail::check_name(block_name, "snapshot block");
  m.check_step(time, block_name);
  const auto interior = static_cast<std::size_t>(grid.interior_size());
  const auto with_ghosts = static_cast<std::size_t>(grid.size());
  auto check_size = [&](const std::string& name, std::size_t size) {
    if (size != interior && size != with_ghosts)
      throw core::Error(fmt::format(
          "io: field '{}' of block '{}' has {} values; expected {} (interior nodes) or {} (with ghost layer)",
          name, block_name, size, interior, with_ghosts));
  };
  std::set<std::string> field_names;
  for (const auto& [name, values] : scalar_fields) {
    detail::check_name(name, "snapshot field");
    check_size(name, values.size());
    field_names.insert(name);
  }
  for (const auto& [name, comps] : vector_fields) {
    detail::check_name(name, "snapshot field");
    if (!field_names.insert(name).second)
      throw core::Error("io: field '" + name + "' of block '" + block_name + "' is both scalar and vector");
    for (const auto& c : comps) check_size(name, c.size());
  }

  // Slowest axis first, as in HDF5 and XDMF: [nz][ny][nx] (3D), [ny][nx] (2D).
  std::vector<hsize_t> shape;
  for (int a = D - 1; a >= 0; --a) shape.push_back(static_cast<hsize_t>(grid.n()[a]));
  std::vector<hsize_t> vector_shape = shape;
  vector_shape.push_back(3);
  // Interior values x fastest, from either layout.
  auto interior_value = [&](std::span<const double> f, std::size_t linear, const Index<D>& ijk) {
    return f.size() == interior ? f[linear] : f[static_cast<std::size_t>(grid.index(ijk))];
  };

  detail::translate_h5_errors("writing the snapshot file", m.h5_path, [&] {
    Step& step = m.step_for(time, block_name);
    H5::Group g = m.h5->createGroup(step.group + "/" + block_name);
    std::vector<int> n(grid.n().begin(), grid.n().end());
    detail::write_int_attribute(g, "n", n);
    detail::write_double_attribute(g, "origin",
                                   std::vector<double>(grid.origin().data(), grid.origin().data() + D));
    detail::write_double_attribute(g, "dx", {grid.dx()});

    std::vector<double> buffer;
    for (const auto& [name, values] : scalar_fields) {
      const double* data = values.data();
      if (values.size() != interior) {
        buffer.resize(interior);
        std::size_t linear = 0;
        field::for_each_interior(grid, [&](const Index<D>& ijk) {
          buffer[linear] = interior_value(values, linear, ijk);
          ++linear;
        });
        data = buffer.data();
      }
      detail::write_dataset(g, name, shape, data);
    }
    for (const auto& [name, comps] : vector_fields) {
      buffer.assign(3 * interior, 0.0);
      std::size_t linear = 0;
      field::for_each_interior(grid, [&](const Index<D>& ijk) {
        for (int a = 0; a < D; ++a) buffer[3 * linear + a] = interior_value(comps[a], linear, ijk);
        ++linear;
      });
      detail::write_dataset(g, name, vector_shape, buffer.data());
    }

    // XDMF: a 2D block is one layer of a 3DCoRectMesh (see the file header).
    const std::string path = "/" + step.group + "/" + block_name + "/";
    const Vec<D>& o = grid.origin();
    const double dx = grid.dx();
    const std::string dims = D == 3 ? join(shape) : "1 " + join(shape);
    const std::string origin =
        D == 3 ? fmt::format("{} {} {}", o[2], o[1], o[0]) : fmt::format("0 {} {}", o[1], o[0]);
    std::string xml = fmt::format(
        "        <Grid Name=\"{}\" GridType=\"Uniform\">\n"
        "          <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{}\"/>\n"
        "          <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
        "            <DataItem Name=\"Origin\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
        "Format=\"XML\">{}</DataItem>\n"
        "            <DataItem Name=\"Spacing\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
        "Format=\"XML\">{} {} {}</DataItem>\n"
        "          </Geometry>\n",
        block_name, dims, origin, dx, dx, dx);
    for (const auto& [name, values] : scalar_fields) xml += m.attribute(name, false, path + name, shape);
    for (const auto& [name, comps] : vector_fields) xml += m.attribute(name, true, path + name, vector_shape);
    xml += "        </Grid>\n";
    step.grids_xml.push_back(std::move(xml));
    m.publish();
  });
}

template <int D>
void SnapshotWriter<D>::add_mesh_step(double time, const std::string& name, std::span<const Vec<D>> points,
                                      std::span<const std::array<int, D>> cells,
                                      const ScalarFields& point_scalars,
                                      const PointVectorFields& point_vectors) {
  Impl& m = *impl_;
  detail::check_name(name, "snapshot mesh");
  m.check_step(time, name);
  const std::size_t n_points = points.size();
  if (n_points == 0 || cells.empty())
    throw core::Error("io: mesh '" + name + "' needs at least one point and one cell");
  for (const auto& cell : cells)
    for (int v : cell)
      if (v < 0 || static_cast<std::size_t>(v) >= n_points)
        throw core::Error(fmt::format("io: mesh '{}' has a cell referring to node {}; nodes are 0 ... {}",
                                      name, v, n_points - 1));
  std::set<std::string> field_names{"points", "connectivity"};
  auto check_field = [&](const std::string& field, std::size_t size) {
    detail::check_name(field, "mesh field");
    if (!field_names.insert(field).second)
      throw core::Error("io: field name '" + field + "' of mesh '" + name + "' is reserved or given twice");
    if (size != n_points)
      throw core::Error(fmt::format("io: field '{}' of mesh '{}' has {} values; expected {} (one per point)",
                                    field, name, size, n_points));
  };
  for (const auto& [field, values] : point_scalars) check_field(field, values.size());
  for (const auto& [field, values] : point_vectors) check_field(field, values.size());

  const std::vector<hsize_t> scalar_shape{n_points};
  const std::vector<hsize_t> vector_shape{n_points, 3};
  const std::vector<hsize_t> cell_shape{cells.size(), static_cast<hsize_t>(D)};
  auto padded = [&](std::span<const Vec<D>> v) {
    std::vector<double> out(3 * v.size(), 0.0);
    for (std::size_t i = 0; i < v.size(); ++i)
      for (int a = 0; a < D; ++a) out[3 * i + a] = v[i][a];
    return out;
  };

  detail::translate_h5_errors("writing the snapshot file", m.h5_path, [&] {
    Step& step = m.step_for(time, name);
    H5::Group g = m.h5->createGroup(step.group + "/" + name);
    detail::write_dataset(g, "points", vector_shape, padded(points).data());
    std::vector<int> connectivity;
    connectivity.reserve(D * cells.size());
    for (const auto& cell : cells) connectivity.insert(connectivity.end(), cell.begin(), cell.end());
    detail::write_dataset(g, "connectivity", cell_shape, connectivity.data());
    for (const auto& [field, values] : point_scalars)
      detail::write_dataset(g, field, scalar_shape, values.data());
    for (const auto& [field, values] : point_vectors)
      detail::write_dataset(g, field, vector_shape, padded(values).data());

    const std::string path = "/" + step.group + "/" + name + "/";
    const std::string topology =
        D == 2 ? fmt::format(R"(TopologyType="Polyline" NodesPerElement="2" NumberOfElements="{}")",
                             cells.size())
               : fmt::format(R"(TopologyType="Triangle" NumberOfElements="{}")", cells.size());
    std::string xml = fmt::format(
        "        <Grid Name=\"{}\" GridType=\"Uniform\">\n"
        "          <Topology {}>\n"
        "            {}\n"
        "          </Topology>\n"
        "          <Geometry GeometryType=\"XYZ\">\n"
        "            {}\n"
        "          </Geometry>\n",
        name, topology, m.data_item(path + "connectivity", cell_shape, /*integer=*/true),
        m.data_item(path + "points", vector_shape));
    for (const auto& [field, values] : point_scalars)
      xml += m.attribute(field, false, path + field, scalar_shape);
    for (const auto& [field, values] : point_vectors)
      xml += m.attribute(field, true, path + field, vector_shape);
    xml += "        </Grid>\n";
    step.grids_xml.push_back(std::move(xml));
    m.publish();
  });
}

template <int D>
void SnapshotWriter<D>::close() {
  Impl& m = *impl_;
  if (!m.open) return;
  detail::translate_h5_errors("closing the snapshot file", m.h5_path, [&] {
    m.h5->close();
    m.h5.reset();
  });
  m.open = false;
}

template <int D>
std::size_t SnapshotWriter<D>::steps() const {
  return impl_->steps.size();
}
template <int D>
const fs::path& SnapshotWriter<D>::h5_file() const {
  return impl_->h5_path;
}
template <int D>
const fs::path& SnapshotWriter<D>::xdmf_file() const {
  return impl_->xdmf_path;
}

std::vector<std::array<int, 2>> closed_ring_segments(int n) {
  CAPLAB_CHECK(n >= 2, "io: a closed ring needs at least two nodes");
  std::vector<std::array<int, 2>> segments(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) segments[static_cast<std::size_t>(i)] = {i, (i + 1) % n};
  return segments;
}

template class SnapshotWriter<2>;
template class SnapshotWriter<3>;

}  // namespace caplab::io
