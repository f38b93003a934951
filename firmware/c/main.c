/* The attitude navigator's main loop in C on a Cortex-M4F, against libestimator_c.a (the C
   interface of estimator-core, include/estimator.h). It is the attitude part of
   firmware/src/starter.rs: a stand-in board (a level body at rest for 2 s, then turning about
   the vertical at 10 deg/s; IMU at 200 Hz, magnetometer at 50 Hz, a small deterministic noise)
   fed one timestamped sample at a time, every outcome handled, the estimate printed once a
   second, and after 10 s a self-check against the stand-in's truth: tilt and heading valid and
   the attitude within 2 deg. It exits with status 0 under QEMU when the check passes.

   Build and run: bash .ci/c.sh (firmware step). Three parts are stand-ins, each marked
   REPLACE: the board (your drivers and clock), the output (semihosting.h: your UART), and the
   self-check (your firmware runs forever). */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "estimator.h"
#include "semihosting.h"

#define IMU_HZ 200u
#define STEP_NS (1000000000ull / IMU_HZ)
#define TURN_RATE 0.17453293f /* rad/s: 10 deg/s */

/* The world magnetic field, uT, ENU (north along y, pointing down). */
static const float FIELD[3] = {0.0f, 20.0f, -45.0f};

/* The navigator's storage: static, no heap. est_attitude_storage_size() bytes at least, aligned
   to est_attitude_storage_align() (both checked at start-up). */
static union {
    unsigned char bytes[2048];
    uint64_t align;
} nav_storage;

/* ---- output (REPLACE with your telemetry) ---- */

static void put(const char *s) {
    semihosting_write(s);
}

static void put_int(int32_t v) {
    char buf[12];
    int i = (int)sizeof buf - 1;
    uint32_t u = v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
    buf[i] = '\0';
    do {
        buf[--i] = (char)('0' + u % 10u);
        u /= 10u;
    } while (u != 0u && i > 1);
    if (v < 0) {
        buf[--i] = '-';
    }
    put(&buf[i]);
}

/* ---- the stand-in board (REPLACE with your drivers and clock) ---- */

/* sin and cos of x, for the stand-in's simulated sensors only (no libm here). */
static void sin_cos(float x, float *s, float *c) {
    const float pi = 3.14159265f;
    float x2;
    while (x > pi) {
        x -= 2.0f * pi;
    }
    while (x < -pi) {
        x += 2.0f * pi;
    }
    x2 = x * x;
    *s = x * (1.0f - x2 / 6.0f * (1.0f - x2 / 20.0f * (1.0f - x2 / 42.0f * (1.0f - x2 / 72.0f *
                                                                         (1.0f - x2 / 110.0f)))));
    *c = 1.0f - x2 / 2.0f * (1.0f - x2 / 12.0f * (1.0f - x2 / 30.0f * (1.0f - x2 / 56.0f *
                                                                    (1.0f - x2 / 90.0f *
                                                                               (1.0f - x2 / 132.0f)))));
}

/* The body's yaw at sample k, rad. */
static float board_yaw(uint32_t k) {
    float t = (float)k / (float)IMU_HZ;
    return t < 2.0f ? 0.0f : TURN_RATE * (t - 2.0f);
}

/* A noise in [-s, s]. */
static float board_noise(uint32_t k, uint32_t axis, float s) {
    uint64_t x = ((uint64_t)k * 6364136223846793005ull + (uint64_t)axis * 1442695040888963407ull) >> 40;
    return ((float)(uint32_t)x / 16777216.0f - 0.5f) * 2.0f * s;
}

static uint64_t board_time_ns(uint32_t k) {
    return 1000000000ull + (uint64_t)k * STEP_NS;
}

static void board_imu(uint32_t k, float gyro[3], float accel[3]) {
    float rate = board_yaw(k) > 0.0f ? TURN_RATE : 0.0f;
    gyro[0] = 0.002f + board_noise(k, 0, 0.003f);
    gyro[1] = -0.001f + board_noise(k, 1, 0.003f);
    gyro[2] = rate + board_noise(k, 2, 0.003f);
    accel[0] = board_noise(k, 3, 0.03f);
    accel[1] = board_noise(k, 4, 0.03f);
    accel[2] = 9.81f + board_noise(k, 5, 0.03f);
}

/* The field in the body frame (the world field turned by -yaw), every fourth sample. */
static bool board_magnetometer(uint32_t k, float field[3]) {
    float s, c;
    if (k % 4u != 0u) {
        return false;
    }
    sin_cos(board_yaw(k), &s, &c);
    field[0] = c * FIELD[0] + s * FIELD[1] + board_noise(k, 6, 0.3f);
    field[1] = -s * FIELD[0] + c * FIELD[1] + board_noise(k, 7, 0.3f);
    field[2] = FIELD[2] + board_noise(k, 8, 0.3f);
    return true;
}

/* ---- the main loop ---- */

static void refused(const char *what, est_error err) {
    put(what);
    put(" refused: ");
    put(est_error_name(err));
    put("\n");
}

int main(void) {
    est_attitude_config cfg;
    est_attitude *nav = NULL;
    est_attitude_estimate e;
    est_attitude_report r;
    est_error err;
    uint32_t k;
    float s, c, dot;

    /* The library must be the interface this file was compiled against. */
    if (est_api_version() >> 16 != EST_API_VERSION >> 16) {
        put("FAIL: library and header versions differ\n");
        return 1;
    }
    if (est_attitude_storage_size() > sizeof nav_storage.bytes ||
        est_attitude_storage_align() > sizeof nav_storage.align) {
        put("FAIL: the navigator's storage is too small\n");
        return 1;
    }

    /* The sensor's noise (from its data sheet, or measured by host-sim calibrate) and the
       magnetometer with its reference field; everything else stays at the defaults. */
    est_attitude_config_default(&cfg);
    cfg.gyro_noise_density = 2e-4f;
    cfg.gyro_random_walk = 2e-5f;
    cfg.accel_noise_density = 2e-3f;
    cfg.accel_random_walk = 3e-3f;
    cfg.has_magnetometer = true;
    cfg.magnetometer_sigma = 0.3f;
    cfg.has_magnetometer_reference = true;
    cfg.magnetometer_reference[0] = FIELD[0];
    cfg.magnetometer_reference[1] = FIELD[1];
    cfg.magnetometer_reference[2] = FIELD[2];
    err = est_attitude_init(nav_storage.bytes, sizeof nav_storage.bytes, &cfg, &nav);
    if (err != EST_OK) {
        refused("configuration", err);
        return 1;
    }

    for (k = 1; k <= 10u * IMU_HZ; k++) {
        float gyro[3], accel[3], field[3];
        uint64_t t_ns = board_time_ns(k);
        board_imu(k, gyro, accel);
        /* A refused sample leaves the navigator as it was: log it and go on. */
        err = est_attitude_imu(nav, t_ns, gyro, accel);
        if (err != EST_OK) {
            refused("IMU sample", err);
        } else if (est_attitude_get_report(nav, &r) == EST_OK &&
                   r.event == EST_ATTITUDE_EVENT_STARTED) {
            put("navigator started\n");
        }
        if (board_magnetometer(k, field)) {
            err = est_attitude_magnetometer(nav, t_ns, field);
            if (err != EST_OK) {
                refused("magnetometer sample", err);
            }
        }
        if (k % IMU_HZ == 0u && est_attitude_get_estimate(nav, &e) == EST_OK) {
            /* Integers (micro-units, millidegrees): no float formatting needed. */
            put_int((int32_t)(k / IMU_HZ));
            put(" s q = (");
            put_int((int32_t)(e.quaternion[0] * 1e6f));
            put(", ");
            put_int((int32_t)(e.quaternion[1] * 1e6f));
            put(", ");
            put_int((int32_t)(e.quaternion[2] * 1e6f));
            put(", ");
            put_int((int32_t)(e.quaternion[3] * 1e6f));
            put(") e-6, 1-sigma heading ");
            put_int((int32_t)(e.sigma_heading * 57295.78f));
            put(" mdeg\n");
        }
    }

    /* REPLACE: the self-check against the stand-in's truth (your firmware keeps looping). The
       truth is a rotation by the yaw about up, q = (cos(yaw/2), 0, 0, sin(yaw/2)); within 2 deg
       means |<q, truth>| = cos(angle/2) > cos(1 deg). */
    if (est_attitude_get_estimate(nav, &e) != EST_OK || est_attitude_get_report(nav, &r) != EST_OK) {
        put("FAIL: no estimate after 10 s\n");
        return 1;
    }
    sin_cos(board_yaw(10u * IMU_HZ) / 2.0f, &s, &c);
    dot = e.quaternion[0] * c + e.quaternion[3] * s;
    if (dot < 0.0f) {
        dot = -dot;
    }
    if (r.tilt.valid && r.heading.valid && dot > 0.99984770f) {
        put("PASS after 10 s: attitude within 2 deg, tilt and heading valid\n");
        return 0;
    }
    put("FAIL after 10 s: tilt valid ");
    put_int(r.tilt.valid);
    put(", heading valid ");
    put_int(r.heading.valid);
    put(", |<q, truth>| e-6 ");
    put_int((int32_t)(dot * 1e6f));
    put("\n");
    return 1;
}
