// SPDX-License-Identifier: BSD-3-Clause
// rotacal-kins: a LinuxCNC 2.9 (uspace) kinematics module that runs a rotacal model blob
// (`rotacal export --controller realtime`) in the servo thread, with every term of the model,
// through the real-time headers (include/rotacal/realtime/): the formulas the fits use.
//
//   loadrt rotacal-kins model=/path/ac.rtb[,/path/bc.rtb[,...]] coordinates=XYZAC
//
// Up to three models; with more than one, motion.switchkins-type selects the one in use (0 the
// first). Joint i is the axis letter coordinates[i]; X, Y, Z and each model's rotary letters must
// be there once; other letters pass through. World X, Y, Z: the tool tip relative to the
// workpiece (the model's table frame, mm); world rotary coordinates: the nominal angles (deg)
// whose nominal tool direction is the actual one (realtime::forward_world / inverse).
// Pins: rotacal-kins.tool-offset (mm, as the trt kinematics': the tip below the controlled
// point, or the tool length on a head), rotacal-kins.y1 and .y2 (the thermal lag states, fed by
// the HAL chain that integrates them), rotacal-kins.inverse-residual (mm, out).
// Loading (rtapi_app_main) is the only step that may fail: it names the file and the field.
// docs/linuxcnc_kins.md: how to build, install and load it.

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "emcpos.h"  // C++-aware (posemath); kinematics.h is not, so it is read as C below
#include "hal.h"
#include "rtapi.h"
#include "rtapi_bool.h"
extern "C" {
#include "kinematics.h"
#include "rtapi_app.h"
}

#include "rotacal/realtime/blob.hpp"
#include "rotacal/realtime/evaluate.hpp"

namespace {

namespace rt = rotacal::realtime;

constexpr int kMaxModels = 3;  // switchkins types 0, 1, 2 (LinuxCNC's SWITCHKINS_MAX_TYPES)
constexpr int kMaxJoints = 9;  // EmcPose's letters X Y Z A B C U V W
constexpr const char* kLetters = "XYZABCUVW";
constexpr double kRad = M_PI / 180.0;

struct Pins {
  hal_float_t* tool_offset;
  hal_float_t* y1;
  hal_float_t* y2;
  hal_float_t* inverse_residual;
};

// Filled once by rtapi_app_main, read by the servo thread.
rt::Model g_models[kMaxModels];
int g_num_models = 0;
int g_active = 0;
int g_joint_of_letter[kMaxJoints];  // -1: the letter has no joint
int g_num_joints = 0;
Pins* g_pins = nullptr;
int g_comp_id = -1;
unsigned char g_file[1 << 16];  // a blob of the largest model is under 6 kB

double& pose_letter(EmcPose& p, int letter) {
  double* v[kMaxJoints] = {&p.tran.x, &p.tran.y, &p.tran.z, &p.a, &p.b, &p.c, &p.u, &p.v, &p.w};
  return *v[letter];
}

int letter_index(char c) {
  const char* at = std::strchr(kLetters, c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
  return at && c ? static_cast<int>(at - kLetters) : -1;
}

// Joint of the model's chain axis k (its letter's joint).
int joint_of_axis(const rt::Model& m, int k) {
  return g_joint_of_letter[letter_index(m.axes[k].name)];
}

rt::State state() {
  rt::State s;
  s.tool_length = *g_pins->tool_offset;
  s.y1 = *g_pins->y1;
  s.y2 = *g_pins->y2;
  return s;
}

int tilt_index(const rt::Model& m) { return 1 - m.rot; }

}  // namespace

extern "C" {

char* model[kMaxModels];
RTAPI_MP_ARRAY_STRING(model, kMaxModels, "model blob files (rotacal export --controller realtime)")
char* coordinates = nullptr;
RTAPI_MP_STRING(coordinates, "axis letter of each joint, e.g. XYZAC (default XYZ + the model's)")
MODULE_LICENSE("Dual BSD/GPL");
MODULE_DESCRIPTION("rotacal identified-model kinematics (rotacal-kins)");

int kinematicsForward(const double* joint, EmcPose* world, const KINEMATICS_FORWARD_FLAGS*,
                      KINEMATICS_INVERSE_FLAGS*) {
  const rt::Model& m = g_models[g_active];
  for (int l = 0; l < kMaxJoints; ++l)  // letters the model does not move pass through
    pose_letter(*world, l) = g_joint_of_letter[l] >= 0 ? joint[g_joint_of_letter[l]] : 0.0;
  rt::Joints q;
  for (int i = 0; i < 3; ++i) q.xyz[i] = joint[g_joint_of_letter[i]];
  q.angles.tilt = joint[joint_of_axis(m, tilt_index(m))] * kRad;
  q.angles.rot = joint[joint_of_axis(m, m.rot)] * kRad;
  const rt::Joints w = rt::forward_world(m, q, state());
  world->tran.x = w.xyz.x();
  world->tran.y = w.xyz.y();
  world->tran.z = w.xyz.z();
  pose_letter(*world, letter_index(m.axes[tilt_index(m)].name)) = w.angles.tilt / kRad;
  pose_letter(*world, letter_index(m.axes[m.rot].name)) = w.angles.rot / kRad;
  return 0;
}

int kinematicsInverse(const EmcPose* world, double* joint, const KINEMATICS_INVERSE_FLAGS*,
                      KINEMATICS_FORWARD_FLAGS*) {
  const rt::Model& m = g_models[g_active];
  EmcPose& p = const_cast<EmcPose&>(*world);  // read only: pose_letter has one signature
  for (int l = 0; l < kMaxJoints; ++l)
    if (g_joint_of_letter[l] >= 0) joint[g_joint_of_letter[l]] = pose_letter(p, l);
  rt::Joints w;
  w.xyz = Eigen::Vector3d(world->tran.x, world->tran.y, world->tran.z);
  w.angles.tilt = pose_letter(p, letter_index(m.axes[tilt_index(m)].name)) * kRad;
  w.angles.rot = pose_letter(p, letter_index(m.axes[m.rot].name)) * kRad;
  const rt::InverseResult r = rt::inverse(m, w, state());
  for (int i = 0; i < 3; ++i) joint[g_joint_of_letter[i]] = r.joints.xyz[i];
  joint[joint_of_axis(m, tilt_index(m))] = r.joints.angles.tilt / kRad;
  joint[joint_of_axis(m, m.rot)] = r.joints.angles.rot / kRad;
  *g_pins->inverse_residual = r.tip_error;
  return 0;
}

KINEMATICS_TYPE kinematicsType(void) { return KINEMATICS_BOTH; }

int kinematicsSwitchable(void) { return g_num_models > 1; }

int kinematicsSwitch(int switchkins_type) {
  if (switchkins_type < 0 || switchkins_type >= g_num_models) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: switchkins-type %d: no such model (%d loaded)\n",
                    switchkins_type, g_num_models);
    return -1;
  }
  g_active = switchkins_type;
  return 0;
}

EXPORT_SYMBOL(kinematicsForward);
EXPORT_SYMBOL(kinematicsInverse);
EXPORT_SYMBOL(kinematicsType);
EXPORT_SYMBOL(kinematicsSwitchable);
EXPORT_SYMBOL(kinematicsSwitch);

}  // extern "C"

namespace {

// Reads model file k into g_models[k]; false (after naming file and field) when refused.
bool load_model(int k, const char* path) {
  std::FILE* f = std::fopen(path, "rb");
  if (!f) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: model[%d] %s: cannot open: %s\n", k, path,
                    std::strerror(errno));
    return false;
  }
  const std::size_t n = std::fread(g_file, 1, sizeof g_file, f);
  const bool too_long = n == sizeof g_file && std::fgetc(f) != EOF;
  std::fclose(f);
  if (too_long) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: model[%d] %s: length: over %zu bytes\n", k, path,
                    sizeof g_file);
    return false;
  }
  const rt::LoadResult r = rt::decode(g_file, n, 0, g_models[k]);
  if (!r.ok) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: model[%d] %s: %s%s%d%s: %s\n", k, path, r.field,
                    r.index >= 0 ? "[" : "", r.index >= 0 ? r.index : 0, r.index >= 0 ? "]" : "",
                    r.reason);
    return false;
  }
  if (g_models[k].axes[0].name == g_models[k].axes[1].name) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: model[%d] %s: axes.name: both axes are %c\n", k,
                    path, g_models[k].axes[0].name);
    return false;
  }
  return true;
}

// coordinates -> g_joint_of_letter; every letter a model moves needs its joint.
bool map_joints() {
  // Default: XYZ and the first model's two letters in alphabetical order.
  const char a = g_models[0].axes[0].name, b = g_models[0].axes[1].name;
  const char deflt[6] = {'X', 'Y', 'Z', a < b ? a : b, a < b ? b : a, 0};
  const char* c = coordinates && *coordinates ? coordinates : deflt;
  for (int& j : g_joint_of_letter) j = -1;
  g_num_joints = 0;
  for (; *c; ++c) {
    if (*c == ' ') continue;
    const int l = letter_index(*c);
    if (l < 0 || g_joint_of_letter[l] >= 0 || g_num_joints == kMaxJoints) {
      rtapi_print_msg(RTAPI_MSG_ERR,
                      "rotacal-kins: coordinates=%s: '%c' is not a new letter of XYZABCUVW\n",
                      coordinates, *c);
      return false;
    }
    g_joint_of_letter[l] = g_num_joints++;
  }
  for (int i = 0; i < 3; ++i)
    if (g_joint_of_letter[i] < 0) {
      rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: coordinates: %c has no joint\n", kLetters[i]);
      return false;
    }
  for (int k = 0; k < g_num_models; ++k)
    for (const rt::Axis& ax : g_models[k].axes)
      if (g_joint_of_letter[letter_index(ax.name)] < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "rotacal-kins: model[%d] %s: axes.name: %c is not in coordinates\n", k,
                        model[k], ax.name);
        return false;
      }
  return true;
}

}  // namespace

extern "C" int rtapi_app_main(void) {
  g_num_models = 0;
  for (int k = 0; k < kMaxModels && model[k] && *model[k]; ++k) {
    if (!load_model(k, model[k])) return -EINVAL;
    ++g_num_models;
  }
  if (g_num_models == 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: model: no model blob given (model=FILE)\n");
    return -EINVAL;
  }
  if (!map_joints()) return -EINVAL;
  g_active = 0;
  g_comp_id = hal_init("rotacal-kins");
  if (g_comp_id < 0) return g_comp_id;
  g_pins = static_cast<Pins*>(hal_malloc(sizeof(Pins)));
  int res = g_pins ? 0 : -ENOMEM;
  if (!res)
    res = hal_pin_float_newf(HAL_IN, &g_pins->tool_offset, g_comp_id, "rotacal-kins.tool-offset");
  if (!res) res = hal_pin_float_newf(HAL_IN, &g_pins->y1, g_comp_id, "rotacal-kins.y1");
  if (!res) res = hal_pin_float_newf(HAL_IN, &g_pins->y2, g_comp_id, "rotacal-kins.y2");
  if (!res)
    res = hal_pin_float_newf(HAL_OUT, &g_pins->inverse_residual, g_comp_id,
                             "rotacal-kins.inverse-residual");
  if (res) {
    rtapi_print_msg(RTAPI_MSG_ERR, "rotacal-kins: cannot export its pins (%d)\n", res);
    hal_exit(g_comp_id);
    return res;
  }
  rtapi_print_msg(RTAPI_MSG_INFO, "rotacal-kins: %d model(s), %d joints\n", g_num_models,
                  g_num_joints);
  hal_ready(g_comp_id);
  return 0;
}

extern "C" void rtapi_app_exit(void) { hal_exit(g_comp_id); }
