// Embree's memory for a triangle mesh (the peers' harness measures its time, not its memory):
// the device's memory monitor counts every allocation. Prints the geometry buffers' bytes, the
// bytes the build keeps (the BVH and its primitive blocks) and the peak during the build, for
// MEDIUM and HIGH. Reads an OBJ as `seethru export` writes it. Build and run (after
// `bash ../shared/peers/setup.sh` and the peers' `embree_native/build.sh`, whose Embree 4.4
// library and 4.2 headers it uses):
//
//   LIB4=$(ls ../shared/peers/.venv/lib/python3*/site-packages/embreex.libs/libembree4-*.so.4)
//   g++ -O2 -std=c++17 -I$(ls -d ~/.cargo/registry/src/*/embree4-sys-0.0.12/lib) \
//       docs/notebook/embree_memory.cpp -o /tmp/embree_memory "$LIB4" -Wl,-rpath,$(dirname "$LIB4")
//   /tmp/embree_memory scene.obj threads=2
#include <embree4/rtcore.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
static long long cur = 0, peak = 0;
static bool monitor(void*, ssize_t bytes, bool) { cur += bytes; if (cur > peak) peak = cur; return true; }
int main(int argc, char** argv) {
  FILE* f = fopen(argv[1], "rb"); std::string text; char buf[1 << 16]; size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  std::vector<float> V; std::vector<unsigned> F; const char* p = text.c_str();
  while (*p) {
    const char* eol = strchr(p, '\n'); if (!eol) eol = p + strlen(p);
    if (p[0] == 'v' && p[1] == ' ') { char* q = (char*)p + 2; for (int k = 0; k < 3; k++) V.push_back((float)strtod(q, &q)); }
    else if (p[0] == 'f' && p[1] == ' ') { char* q = (char*)p + 2; long nv = V.size() / 3;
      for (int k = 0; k < 3; k++) { long i = strtol(q, &q, 10); while (*q && *q != ' ' && *q != '\n') q++; F.push_back(i < 0 ? nv + i : i - 1); } }
    p = *eol ? eol + 1 : eol;
  }
  size_t nv = V.size() / 3, nt = F.size() / 3;
  for (RTCBuildQuality q : {RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_HIGH}) {
    RTCDevice dev = rtcNewDevice(argc > 2 ? argv[2] : nullptr);
    rtcSetDeviceMemoryMonitorFunction(dev, monitor, nullptr);
    cur = peak = 0;
    RTCScene scene = rtcNewScene(dev); rtcSetSceneBuildQuality(scene, q);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* vb = (float*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 16, nv);
    for (size_t i = 0; i < nv; i++) for (int k = 0; k < 4; k++) vb[4 * i + k] = k < 3 ? V[3 * i + k] : 0.0f;
    unsigned* ib = (unsigned*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nt);
    memcpy(ib, F.data(), F.size() * 4);
    rtcCommitGeometry(g); rtcAttachGeometry(scene, g); rtcReleaseGeometry(g);
    long long before = cur; peak = cur;
    rtcCommitScene(scene);
    printf("%s: %zu triangles, %zu vertices; buffers %.1f MB (monitor), built structure %.1f MB = %.1f B/triangle, peak during build +%.1f MB\n",
           q == RTC_BUILD_QUALITY_HIGH ? "HIGH" : "MEDIUM", nt, nv, before / 1e6, (cur - before) / 1e6,
           double(cur - before) / nt, (peak - before) / 1e6);
    rtcReleaseScene(scene); rtcReleaseDevice(dev);
  }
}
