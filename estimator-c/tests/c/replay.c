/* Feeds an IMU + magnetometer stream through the C interface of the attitude navigator and
   prints, after every sample, the return code and the estimate and report as hex bit patterns
   (tests/replay.rs compares them with estimator-core's own navigator, bit for bit).

   Input (stdin), one sample a line, floats as the hex of their IEEE-754 bits:
     I <t_ns> <gx> <gy> <gz> <ax> <ay> <az>      IMU: rad/s, m/s^2, body frame
     M <t_ns> <mx> <my> <mz>                     magnetometer: uT, body frame
   Output (stdout), one line a sample:
     <code> -                                    before the first estimate
     <code> <t_ns> <q w x y z> <gyro bias> <accel bias> <sigma tilt> <sigma heading>
            <tilt valid/reason> <heading valid/reason> <magnetic status> <event>
   and at the end a line of counters. */
#include "estimator.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

/* The storage of the navigator: static, aligned for any type the navigator holds. */
static union {
    unsigned char bytes[16384];
    uint64_t align_u64;
    double align_double;
} storage;

static float from_bits(uint32_t bits) {
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static uint32_t to_bits(float f) {
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    return bits;
}

static void print_floats(const float *v, int n) {
    int i;
    for (i = 0; i < n; i++) {
        printf(" %08" PRIx32, to_bits(v[i]));
    }
}

int main(void) {
    est_attitude_config cfg;
    est_attitude *nav = NULL;
    char kind;
    uint64_t t_ns;
    uint32_t b[6];
    est_error err;

    if (est_api_version() >> 16 != EST_API_VERSION >> 16) {
        fprintf(stderr, "library version %" PRIu32 " does not match the header's\n", est_api_version());
        return 2;
    }
    if (est_attitude_storage_size() > sizeof storage.bytes ||
        est_attitude_storage_align() > sizeof storage.align_u64) {
        fprintf(stderr, "storage: need %zu bytes aligned to %zu\n", est_attitude_storage_size(),
                est_attitude_storage_align());
        return 2;
    }
    est_attitude_config_default(&cfg);
    cfg.instantaneous_imu = true;
    cfg.has_magnetometer = true;
    cfg.magnetometer_sigma = 0.5f;
    cfg.has_magnetometer_reference = true;
    cfg.magnetometer_reference[0] = 0.0f;
    cfg.magnetometer_reference[1] = 20.0f;
    cfg.magnetometer_reference[2] = -45.0f;
    err = est_attitude_init(storage.bytes, sizeof storage.bytes, &cfg, &nav);
    if (err != EST_OK) {
        fprintf(stderr, "init: %s\n", est_error_name(err));
        return 2;
    }

    while (scanf(" %c %" SCNu64, &kind, &t_ns) == 2) {
        est_attitude_estimate e;
        est_attitude_report r;
        if (kind == 'I') {
            float gyro[3], accel[3];
            int i;
            if (scanf("%" SCNx32 " %" SCNx32 " %" SCNx32 " %" SCNx32 " %" SCNx32 " %" SCNx32,
                      &b[0], &b[1], &b[2], &b[3], &b[4], &b[5]) != 6) {
                return 3;
            }
            for (i = 0; i < 3; i++) {
                gyro[i] = from_bits(b[i]);
                accel[i] = from_bits(b[i + 3]);
            }
            err = est_attitude_imu(nav, t_ns, gyro, accel);
        } else if (kind == 'M') {
            float field[3];
            if (scanf("%" SCNx32 " %" SCNx32 " %" SCNx32, &b[0], &b[1], &b[2]) != 3) {
                return 3;
            }
            field[0] = from_bits(b[0]);
            field[1] = from_bits(b[1]);
            field[2] = from_bits(b[2]);
            err = est_attitude_magnetometer(nav, t_ns, field);
        } else {
            return 3;
        }
        printf("%d", (int)err);
        if (est_attitude_get_estimate(nav, &e) == EST_OK &&
            est_attitude_get_report(nav, &r) == EST_OK) {
            printf(" %" PRIu64, e.t_ns);
            print_floats(e.quaternion, 4);
            print_floats(e.gyro_bias, 3);
            print_floats(e.accel_bias, 3);
            print_floats(&e.sigma_tilt, 1);
            print_floats(&e.sigma_heading, 1);
            printf(" %d/%d %d/%d %d %d\n", (int)r.tilt.valid, (int)r.tilt.reason,
                   (int)r.heading.valid, (int)r.heading.reason, (int)r.magnetic, (int)r.event);
        } else {
            printf(" -\n");
        }
    }
    {
        est_attitude_counters c;
        if (est_attitude_get_counters(nav, &c) != EST_OK) {
            return 4;
        }
        printf("counters %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 "\n", c.imu,
               c.magnetometer, c.refused, c.gravity_fused, c.heading_fused);
    }
    return 0;
}
