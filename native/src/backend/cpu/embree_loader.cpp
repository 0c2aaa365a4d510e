#include "backend/cpu/embree_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>

namespace lantern {

#if LANTERN_HAVE_EMBREE
namespace {

struct Loaded {
    EmbreeApi api;
    std::string error;
    std::string path;
    void* handle = nullptr;
};

template <typename F>
void resolve(void* handle, const char* name, F& fn, std::string& error) {
    fn = reinterpret_cast<F>(dlsym(handle, name));
    if (!fn && error.empty()) error = std::string("Embree symbol missing: ") + name;
}

Loaded load() {
    Loaded l;
    const char* env = std::getenv("LANTERN_EMBREE_LIBRARY");
    l.path = env && *env ? env : "libembree3.so.3";
    // RTLD_DEEPBIND: Embree and what it loads resolve their own symbols before the global scope.
    l.handle = dlopen(l.path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
    if (!l.handle) {
        const char* e = dlerror();
        l.error = "cannot load Embree 3 (" + l.path + "): " + (e ? e : "unknown error") +
                  ". Install it (Debian: apt-get install libembree3-3) or set "
                  "LANTERN_EMBREE_LIBRARY to its path.";
        return l;
    }
    EmbreeApi& a = l.api;
    resolve(l.handle, "rtcNewDevice", a.newDevice, l.error);
    resolve(l.handle, "rtcReleaseDevice", a.releaseDevice, l.error);
    resolve(l.handle, "rtcGetDeviceError", a.getDeviceError, l.error);
    resolve(l.handle, "rtcSetDeviceErrorFunction", a.setDeviceErrorFunction, l.error);
    resolve(l.handle, "rtcGetDeviceProperty", a.getDeviceProperty, l.error);
    resolve(l.handle, "rtcNewScene", a.newScene, l.error);
    resolve(l.handle, "rtcReleaseScene", a.releaseScene, l.error);
    resolve(l.handle, "rtcSetSceneFlags", a.setSceneFlags, l.error);
    resolve(l.handle, "rtcSetSceneBuildQuality", a.setSceneBuildQuality, l.error);
    resolve(l.handle, "rtcCommitScene", a.commitScene, l.error);
    resolve(l.handle, "rtcNewGeometry", a.newGeometry, l.error);
    resolve(l.handle, "rtcReleaseGeometry", a.releaseGeometry, l.error);
    resolve(l.handle, "rtcSetNewGeometryBuffer", a.setNewGeometryBuffer, l.error);
    resolve(l.handle, "rtcCommitGeometry", a.commitGeometry, l.error);
    resolve(l.handle, "rtcAttachGeometry", a.attachGeometry, l.error);
    resolve(l.handle, "rtcSetGeometryUserData", a.setGeometryUserData, l.error);
    resolve(l.handle, "rtcSetGeometryIntersectFilterFunction", a.setGeometryIntersectFilterFunction,
            l.error);
    resolve(l.handle, "rtcSetGeometryOccludedFilterFunction", a.setGeometryOccludedFilterFunction,
            l.error);
    resolve(l.handle, "rtcIntersect1", a.intersect1, l.error);
    resolve(l.handle, "rtcOccluded1", a.occluded1, l.error);
    resolve(l.handle, "rtcSetGeometryInstancedScene", a.setGeometryInstancedScene, l.error);
    resolve(l.handle, "rtcSetGeometryTransform", a.setGeometryTransform, l.error);
    resolve(l.handle, "rtcSetGeometryTimeStepCount", a.setGeometryTimeStepCount, l.error);
    resolve(l.handle, "rtcSetGeometryTransformQuaternion", a.setGeometryTransformQuaternion,
            l.error);
    if (l.error.empty()) {
        Dl_info info;
        if (dladdr(reinterpret_cast<void*>(a.newDevice), &info) && info.dli_fname) {
            l.path = info.dli_fname;
        }
    }
    return l;
}

const Loaded& loaded() {
    static Loaded l = load();
    return l;
}

}  // namespace

const EmbreeApi& embree_api() {
    const Loaded& l = loaded();
    if (!l.error.empty()) throw std::runtime_error(l.error);
    return l.api;
}

bool embree_available() { return loaded().error.empty(); }

std::string embree_library_path() { return loaded().path; }

std::string embree_version() {
    const Loaded& l = loaded();
    if (!l.error.empty()) return "unavailable: " + l.error;
    RTCDevice dev = l.api.newDevice("threads=1");
    if (!dev) return "unavailable: rtcNewDevice failed";
    long v = long(l.api.getDeviceProperty(dev, RTC_DEVICE_PROPERTY_VERSION));
    l.api.releaseDevice(dev);
    return std::to_string(v / 10000) + "." + std::to_string((v / 100) % 100) + "." +
           std::to_string(v % 100);
}
#else
bool embree_available() { return false; }
std::string embree_version() { return "unavailable: built without Embree headers"; }
std::string embree_library_path() { return ""; }
#endif

}  // namespace lantern
