#include "open3d/camera/CamerasJson.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "open3d/core/Exception.h"
#include "open3d/core/RegularFile.h"

namespace open3d {
namespace camera {

namespace {

using Json = nlohmann::json;

const Json& Field(const Json& entry, const char* name, const std::string& where) {
    auto it = entry.find(name);
    if (it == entry.end()) core::ThrowError("{}: missing field '{}'", where, name);
    return *it;
}

double Number(const Json& entry, const char* name, const std::string& where) {
    const Json& v = Field(entry, name, where);
    if (!v.is_number()) core::ThrowError("{}: field '{}' must be a number", where, name);
    return v.get<double>();
}

int Integer(const Json& entry, const char* name, const std::string& where) {
    const Json& v = Field(entry, name, where);
    if (!v.is_number_integer()) core::ThrowError("{}: field '{}' must be an integer", where, name);
    const int64_t value =
        v.is_number_unsigned()
            ? static_cast<int64_t>(std::min<uint64_t>(v.get<uint64_t>(), uint64_t(INT64_MAX)))
            : v.get<int64_t>();
    if (value < INT32_MIN || value > INT32_MAX) {
        core::ThrowError("{}: field '{}' = {} is out of range", where, name, value);
    }
    return static_cast<int>(value);
}

Eigen::Vector3d Vec3(const Json& v, const std::string& what) {
    if (!v.is_array() || v.size() != 3) core::ThrowError("{} must be a list of 3 numbers", what);
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i) {
        if (!v[i].is_number()) core::ThrowError("{} must be a list of 3 numbers", what);
        out[i] = v[i].get<double>();
    }
    return out;
}

CameraView ParseEntry(const Json& entry, const std::string& where) {
    if (!entry.is_object()) core::ThrowError("{}: must be an object", where);
    CameraView view;
    view.id = Integer(entry, "id", where);
    if (entry.contains("img_name") && entry["img_name"].is_string()) {
        view.img_name = entry["img_name"].get<std::string>();
    }
    if (entry.contains("time")) {
        const double time = Number(entry, "time", where);
        if (!std::isfinite(time)) core::ThrowError("{}: field 'time' must be finite", where);
        view.time = time;
    }
    PinholeCamera& cam = view.camera;
    cam.width = Integer(entry, "width", where);
    cam.height = Integer(entry, "height", where);
    cam.fx = Number(entry, "fx", where);
    cam.fy = Number(entry, "fy", where);
    if (cam.width <= 0 || cam.height <= 0) {
        core::ThrowError("{}: image size must be positive, got {}x{}", where, cam.width,
                         cam.height);
    }
    if (!(cam.fx > 0 && cam.fy > 0)) {
        core::ThrowError("{}: fx and fy must be positive, got {} {}", where, cam.fx, cam.fy);
    }
    cam.cx = (cam.width - 1) / 2.0;
    cam.cy = (cam.height - 1) / 2.0;
    const Eigen::Vector3d position = Vec3(Field(entry, "position", where), where + ": 'position'");
    const Json& rot = Field(entry, "rotation", where);
    if (!rot.is_array() || rot.size() != 3) {
        core::ThrowError("{}: 'rotation' must be a 3x3 list of rows", where);
    }
    Eigen::Matrix3d camera_to_world;
    for (int r = 0; r < 3; ++r) {
        camera_to_world.row(r) = Vec3(rot[r], where + ": 'rotation' row").transpose();
    }
    const Eigen::Matrix3d world_to_camera = camera_to_world.transpose();
    cam.world_to_camera.setIdentity();
    cam.world_to_camera.topLeftCorner<3, 3>() = world_to_camera;
    cam.world_to_camera.topRightCorner<3, 1>() = -world_to_camera * position;
    try {
        cam.Validate();
    } catch (const core::Open3DError& e) {
        core::ThrowError("{}: {}", where, e.what());
    }
    return view;
}

}  // namespace

std::vector<CameraView> ParseCamerasJson(const std::string& text, const std::string& source_name) {
    Json root;
    try {
        root = Json::parse(text);
    } catch (const Json::exception& e) {  // parse_error, and out_of_range for number overflow
        core::ThrowError("{}: malformed JSON: {}", source_name, e.what());
    }
    if (!root.is_array()) core::ThrowError("{}: expected a JSON list of cameras", source_name);
    std::vector<CameraView> views;
    views.reserve(root.size());
    for (size_t i = 0; i < root.size(); ++i) {
        views.push_back(ParseEntry(root[i], fmt::format("{}: camera entry {}", source_name, i)));
    }
    return views;
}

std::string CamerasJsonText(const std::vector<CameraView>& views) {
    Json root = Json::array();
    for (size_t i = 0; i < views.size(); ++i) {
        const CameraView& view = views[i];
        const PinholeCamera& cam = view.camera;
        cam.Validate();
        if (cam.cx != (cam.width - 1) / 2.0 || cam.cy != (cam.height - 1) / 2.0) {
            core::ThrowError(
                "cameras.json entry {}: principal point ({}, {}) is not the image centre ({}, "
                "{}), which is all the format can hold",
                i, cam.cx, cam.cy, (cam.width - 1) / 2.0, (cam.height - 1) / 2.0);
        }
        const Eigen::Matrix3d camera_to_world = cam.GetRotation().transpose();
        const Eigen::Vector3d position = cam.GetCenter();
        Json entry;
        entry["id"] = view.id;
        entry["img_name"] = view.img_name;
        entry["width"] = cam.width;
        entry["height"] = cam.height;
        entry["position"] = {position.x(), position.y(), position.z()};
        entry["rotation"] = Json::array();
        for (int r = 0; r < 3; ++r) {
            entry["rotation"].push_back(
                {camera_to_world(r, 0), camera_to_world(r, 1), camera_to_world(r, 2)});
        }
        entry["fx"] = cam.fx;
        entry["fy"] = cam.fy;
        if (view.time) entry["time"] = *view.time;
        root.push_back(std::move(entry));
    }
    return root.dump(1) + "\n";
}

void WriteCamerasJson(const std::string& filename, const std::vector<CameraView>& views) {
    const std::string text = CamerasJsonText(views);
    const std::string temp = filename + ".partial";
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        out << text;
        out.close();
        if (!out) {
            std::remove(temp.c_str());
            core::ThrowError("cannot write cameras file '{}'", filename);
        }
    }
    if (std::rename(temp.c_str(), filename.c_str()) != 0) {
        std::remove(temp.c_str());
        core::ThrowError("cannot write cameras file '{}': {}", filename, std::strerror(errno));
    }
}

std::vector<CameraView> ReadCamerasJson(const std::string& filename) {
    core::RequireRegularFile(filename);
    std::ifstream in(filename, std::ios::binary);
    if (!in) core::ThrowError("cannot open cameras file '{}'", filename);
    std::stringstream buffer;
    buffer << in.rdbuf();
    return ParseCamerasJson(buffer.str(), filename);
}

}  // namespace camera
}  // namespace open3d
