// fretbuzz.Case: a case whose fields read and write both as attributes (c.fs) and as
// dictionary items (c["fs"]), named as in the case files; fretbuzz.load_case, cases.
// Every edit is checked whole: the values are set on a copy, the copy is validated, and
// only then does it replace the case, so a failed edit changes nothing.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "Bindings.hpp"
#include "Conversions.hpp"
#include "fretbuzz/Case.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/RunLength.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

struct Field {
    const char* key;
    const char* doc;
    std::function<py::object(const Case&)> get;
    std::function<void(Case&, py::handle)> set;
};

template <typename Group>
Field scalar(const char* key, const char* doc, Group Case::*group, double Group::*member) {
    return {key, doc, [=](const Case& c) { return py::object(py::float_(c.*group.*member)); },
            [=](Case& c, py::handle v) { c.*group.*member = to_number(v, key); }};
}

Field array(const char* key, const char* doc, std::vector<double> Case::*member) {
    return {key, doc, [=](const Case& c) { return py::object(to_read_only_numpy(c.*member)); },
            [=](Case& c, py::handle v) { c.*member = to_vector(v, key); }};
}

void set_mode_column(Case& c, std::vector<double> ModeTable::*column, py::handle v, const char* key) {
    c.modes.*column = to_vector(v, key);
    // New modes (if the table grew) are modelled, not measured.
    c.modes.source.resize(c.modes.frequency_hz.size(), ModeSource::model);
}

const std::vector<Field>& fields() {
    static const std::vector<Field> table = {
        {"name", "case name", [](const Case& c) { return py::object(py::str(c.name)); },
         [](Case& c, py::handle v) { c.name = to_text(v, "name"); }},
        {"description", "one-line description", [](const Case& c) { return py::object(py::str(c.description)); },
         [](Case& c, py::handle v) { c.description = to_text(v, "description"); }},
        scalar("L", "vibrating length (m)", &Case::string, &StringProperties::length_m),
        scalar("T", "tension (N)", &Case::string, &StringProperties::tension_n),
        scalar("mu", "linear density (kg/m)", &Case::string, &StringProperties::linear_density),
        {"frequencies", "modal frequencies nu_j (Hz)", [](const Case& c) { return py::object(to_read_only_numpy(c.modes.frequency_hz)); },
         [](Case& c, py::handle v) { set_mode_column(c, &ModeTable::frequency_hz, v, "frequencies"); }},
        {"sigma", "modal damping sigma_j (1/s)", [](const Case& c) { return py::object(to_read_only_numpy(c.modes.sigma_per_s)); },
         [](Case& c, py::handle v) { set_mode_column(c, &ModeTable::sigma_per_s, v, "sigma"); }},
        array("obstacle_height", "obstacle height g at the grid points (m; -inf: none)", &Case::obstacle_height_m),
        {"point_obstacles", "point obstacles at their exact positions: a list of (x m, height m, width m)",
         [](const Case& c) {
             py::list points;
             for (const PointObstacle& p : c.point_obstacles) points.append(py::make_tuple(p.x_m, p.height_m, p.weight_m));
             return py::object(points);
         },
         [](Case& c, py::handle v) {
             std::vector<PointObstacle> points;
             for (const py::handle item : v) {
                 const std::vector<double> p = to_vector(item, "point_obstacles element");
                 if (p.size() != 3) throw py::type_error("point_obstacles element: expected (x, height, width)");
                 points.push_back({p[0], p[1], p[2]});
             }
             c.point_obstacles = std::move(points);
         }},
        array("initial_displacement", "modal displacement q_j(0)", &Case::initial_displacement),
        array("initial_velocity", "modal velocity dq_j/dt(0)", &Case::initial_velocity),
        scalar("K", "penalty stiffness", &Case::contact, &ContactLaw::stiffness),
        scalar("alpha", "penalty exponent (>= 1)", &Case::contact, &ContactLaw::exponent),
        {"law", "contact law at the obstacle: 'penalty' or 'impact' (Newton's, rigid)",
         [](const Case& c) { return py::object(py::str(contact_law_name(c.contact.law))); },
         [](Case& c, py::handle v) { c.contact.law = contact_law_named(to_text(v, "law"), "law"); }},
        scalar("restitution", "impact law: Newton's restitution coefficient e in [0, 1]", &Case::contact,
               &ContactLaw::restitution),
        scalar("fs", "sampling rate (Hz)", &Case::run, &RunSettings::sample_rate_hz),
        {"duration", "simulated duration (s); setting it cuts the finger and gesture profiles to the run",
         [](const Case& c) { return py::object(py::float_(c.run.duration_s)); },
         [](Case& c, py::handle v) { set_duration(c, to_number(v, "duration")); }},
        {"output_rate", "rows per second of the outputs (Hz), None (or 'native') for every step",
         [](const Case& c) { return c.run.output_rate_hz ? py::object(py::float_(*c.run.output_rate_hz)) : py::object(py::none()); },
         [](Case& c, py::handle v) {
             if (v.is_none() || (py::isinstance<py::str>(v) && v.cast<std::string>() == "native"))
                 c.run.output_rate_hz.reset();
             else if (py::isinstance<py::str>(v))
                 throw py::type_error("output_rate: expected a number (float), None or 'native', got '" +
                                      v.cast<std::string>() + "'");
             else
                 c.run.output_rate_hz = to_number(v, "output_rate");
         }},
        scalar("audio_rate", "sample rate of audio files (Hz)", &Case::run, &RunSettings::audio_rate_hz),
        {"observe", "observation points x (m)", [](const Case& c) { return py::object(py::cast(c.observation_points_m)); },
         [](Case& c, py::handle v) { c.observation_points_m = to_vector(v, "observe"); }},
    };
    return table;
}

const Field& field(const std::string& key) {
    for (const Field& f : fields())
        if (key == f.key) return f;
    std::string known;
    for (const Field& f : fields()) known += std::string(known.empty() ? "" : ", ") + f.key;
    throw py::key_error("no case field '" + key + "'; the fields are: " + known);
}

// Sets several fields at once, all or nothing: on a copy, validated, then swapped in.
void set_fields(Case& c, const py::dict& values) {
    Case edited = c;
    for (const auto& [key, value] : values) {
        if (!py::isinstance<py::str>(key)) throw py::type_error("case field names are str, got " + type_name(key));
        field(key.cast<std::string>()).set(edited, value);
    }
    edited.validate();
    c = std::move(edited);
}

void set_field(Case& c, const std::string& key, py::handle value) {
    py::dict one;
    one[py::str(key)] = value;
    set_fields(c, one);
}

// Pickle state: every field, then what the fields do not show (mode sources, case text).
py::tuple state(const Case& c) {
    py::dict values;
    for (const Field& f : fields()) values[f.key] = f.get(c);
    py::list sources;
    for (ModeSource s : c.modes.source) sources.append(to_string(s));
    return py::make_tuple(values, sources, c.source_text);
}

Case from_state(const py::tuple& t) {
    if (t.size() != 3) throw py::value_error("Case: not a pickled Case");
    Case c;
    for (const auto& [key, value] : t[0].cast<py::dict>()) field(key.cast<std::string>()).set(c, value);
    c.modes.source.clear();
    for (const auto& s : t[1].cast<py::list>())
        c.modes.source.push_back(s.cast<std::string>() == to_string(ModeSource::measured) ? ModeSource::measured
                                                                                          : ModeSource::model);
    c.source_text = t[2].cast<std::string>();
    return c;
}

std::string describe(const Case& c) {
    std::ostringstream out;
    out << "<fretbuzz.Case '" << c.name << "': " << c.mode_count() << " modes, fs = " << c.run.sample_rate_hz
        << " Hz, duration = " << c.run.duration_s << " s>";
    return out.str();
}

}  // namespace

void bind_case(py::module_& m) {
    py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
    py::register_exception<SolverError>(m, "SolverError", PyExc_RuntimeError);

    py::class_<Case> cls(m, "Case",
                         "Case(**fields)\n\n"
                         "A simulation case. Fields read and write as attributes or items, named as in case files:\n"
                         "c.fs = 400000; c['observe'] = [0.854, 0.5]. keys() lists them, to_dict() copies them.\n"
                         "Every edit is validated; a failed edit raises and leaves the case as it was. Arrays are\n"
                         "assigned whole (c.frequencies = new_array); the arrays you read are copies.\n\n"
                         "Case(**fields) builds a case from all its fields (L, T, mu, frequencies, sigma,\n"
                         "obstacle_height, initial_displacement, initial_velocity, fs, duration, observe, ...);\n"
                         "Case.from_toml(text) reads case-file text; load_case(name_or_path) a built-in or a file.");
    cls.def(py::init([](const py::kwargs& values) {
                Case c;
                c.name = "custom";
                set_fields(c, values);
                return c;
            }),
            "Case(**fields) -> Case\n\nA case from keyword fields, validated as a whole.");
    cls.def_static(
        "from_toml",
        [](const std::string& text, const py::object& data_dir) {
            if (data_dir.is_none()) return parse_case(text, "<string>", DataSource::builtin());
            const auto dir = py::str(py::module_::import("os").attr("fspath")(data_dir)).cast<std::string>();
            return parse_case(text, "<string>", DataSource::directory(dir));
        },
        py::arg("text"), py::arg("data_dir") = py::none(),
        "from_toml(text: str, data_dir: str | os.PathLike | None = None) -> Case\n\n"
        "A case from case-file (TOML) text. Data files it names are read from data_dir, or from\n"
        "the built-in cases' data when data_dir is None.");
    for (const Field& f : fields()) {
        const std::string key = f.key;
        cls.def_property(
            f.key, [get = f.get](const Case& c) { return get(c); },
            [key](Case& c, py::handle v) { set_field(c, key, v); }, f.doc);
    }
    cls.def(py::pickle([](const Case& c) { return state(c); }, [](const py::tuple& t) { return from_state(t); }));
    cls.def_property_readonly("modes", &Case::mode_count, "number of modes (= interior grid points)")
        .def_property_readonly(
            "grid_x",
            [](const Case& c) {
                std::vector<double> x(c.mode_count());
                for (std::size_t i = 0; i < x.size(); ++i) x[i] = c.grid_point(i);
                return to_numpy(x);
            },
            "interior grid points x_i (m)")
        .def_readonly("source_text", &Case::source_text, "the case file text this case was read from")
        .def("__getitem__", [](const Case& c, const std::string& key) { return field(key).get(c); })
        .def("__setitem__", [](Case& c, const std::string& key, py::handle v) { set_field(c, key, v); })
        .def("__contains__", [](const Case&, const std::string& key) {
            for (const Field& f : fields())
                if (key == f.key) return true;
            return false;
        })
        .def("keys", [](const Case&) {
            py::list keys;
            for (const Field& f : fields()) keys.append(f.key);
            return keys;
        })
        .def("to_dict", [](const Case& c) {
            py::dict d;
            for (const Field& f : fields()) d[f.key] = f.get(c);
            return d;
        })
        .def("update", &set_fields, py::arg("values"),
             "update(values: dict) -> None\n\nSets several fields at once, validated together: all or nothing.")
        .def("make_lossless", &Case::make_lossless, "Removes all damping (sigma_j = 0).")
        .def("validate", &Case::validate, "Raises InputError (a ValueError) naming the first bad field.")
        .def("copy", [](const Case& c) { return Case(c); })
        .def("__copy__", [](const Case& c) { return Case(c); })
        .def("__deepcopy__", [](const Case& c, py::dict) { return Case(c); })
        .def("__repr__", &describe);

    m.def("load_case", &load_case, py::arg("name_or_path"),
          "A built-in case by name (see cases()) or a .toml case file, as an editable Case.");
    m.def("cases", [] {
        py::dict d;
        for (const BuiltinCaseInfo& info : builtin_cases()) d[py::str(info.name)] = info.description;
        return d;
    }, "The built-in cases: {name: description}.");
}

}  // namespace fretbuzz::python
