// Embree, loaded at run time into a private symbol scope. Blender ships its own Embree 4 that
// exports the same unprefixed rtc* names; inside Blender that library sits in the global scope,
// so a directly linked call could bind to it. We dlopen our Embree with RTLD_LOCAL |
// RTLD_DEEPBIND and call it only through the function pointers resolved from that handle.
#pragma once

#include <string>

#if !defined(LANTERN_NO_EMBREE) && __has_include(<embree3/rtcore.h>)
#include <embree3/rtcore.h>
#define LANTERN_HAVE_EMBREE 1
#else
#define LANTERN_HAVE_EMBREE 0
#endif

namespace lantern {

#if LANTERN_HAVE_EMBREE
struct EmbreeApi {
    decltype(&rtcNewDevice) newDevice = nullptr;
    decltype(&rtcReleaseDevice) releaseDevice = nullptr;
    decltype(&rtcGetDeviceError) getDeviceError = nullptr;
    decltype(&rtcSetDeviceErrorFunction) setDeviceErrorFunction = nullptr;
    decltype(&rtcGetDeviceProperty) getDeviceProperty = nullptr;
    decltype(&rtcNewScene) newScene = nullptr;
    decltype(&rtcReleaseScene) releaseScene = nullptr;
    decltype(&rtcSetSceneFlags) setSceneFlags = nullptr;
    decltype(&rtcSetSceneBuildQuality) setSceneBuildQuality = nullptr;
    decltype(&rtcCommitScene) commitScene = nullptr;
    decltype(&rtcNewGeometry) newGeometry = nullptr;
    decltype(&rtcReleaseGeometry) releaseGeometry = nullptr;
    decltype(&rtcSetNewGeometryBuffer) setNewGeometryBuffer = nullptr;
    decltype(&rtcCommitGeometry) commitGeometry = nullptr;
    decltype(&rtcAttachGeometry) attachGeometry = nullptr;
    decltype(&rtcSetGeometryUserData) setGeometryUserData = nullptr;
    decltype(&rtcSetGeometryIntersectFilterFunction) setGeometryIntersectFilterFunction = nullptr;
    decltype(&rtcSetGeometryOccludedFilterFunction) setGeometryOccludedFilterFunction = nullptr;
    decltype(&rtcIntersect1) intersect1 = nullptr;
    decltype(&rtcOccluded1) occluded1 = nullptr;
    // two-level instancing (embree_instances.cpp)
    decltype(&rtcSetGeometryInstancedScene) setGeometryInstancedScene = nullptr;
    decltype(&rtcSetGeometryTransform) setGeometryTransform = nullptr;
    // motion blur's moving instances (embree_instances.cpp)
    decltype(&rtcSetGeometryTimeStepCount) setGeometryTimeStepCount = nullptr;
    decltype(&rtcSetGeometryTransformQuaternion) setGeometryTransformQuaternion = nullptr;
};

// The process-wide API table, loaded on first use. Throws std::runtime_error with a clear
// message when the library or a symbol is missing.
const EmbreeApi& embree_api();
#endif

bool embree_available();
std::string embree_version();   // "3.13.5", or a reason why it is unavailable
std::string embree_library_path();

}  // namespace lantern
