/*
 * A firmware for `hilsim hil` in plain C (POSIX only), to show that any language works: it
 * knows the two device paths and nothing else of hilsim.
 *
 * It reads the Neato XV-11 lidar stream from $HILSIM_LIDAR_PORT (22-byte packets: 0xFA, index
 * 0xA0..0xF9, rpm x 64, four readings, checksum), takes the distance straight ahead each
 * revolution (the median of the valid readings within +-5 degrees), and drives toward it over
 * $HILSIM_ROBOT_PORT with `SetMotor` steps (Neato command interface: one line out, a reply
 * ending in Ctrl-Z back) until it is at most 500 mm away; then it stops, confirms two more
 * revolutions, prints a summary on stdout and exits.
 *
 * Exit status: 0 target reached; 2 setup failed; 3 a port closed first; 4 the lidar stream had
 * gaps in its packet index sequence (unless run with --allow-gaps, for a link that drops packets).
 *
 * Build: cc -O2 -o firmware firmware.c
 */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#define TARGET_MM 500
#define GAIN 1.5       /* mm/s per mm still to go */
#define MIN_SPEED 40   /* mm/s */
#define MAX_SPEED 250  /* mm/s */
#define HALF_WIDTH 5   /* degrees either side of straight ahead */

static int open_port(const char *path) {
    int fd = open(path, O_RDWR | O_NOCTTY);
    if (fd < 0) return -1;
    struct termios t;
    if (tcgetattr(fd, &t) == 0) {
        cfmakeraw(&t);
        cfsetispeed(&t, B115200);
        cfsetospeed(&t, B115200);
        tcsetattr(fd, TCSANOW, &t);
    }
    return fd;
}

static unsigned checksum(const unsigned char *p) {
    unsigned long acc = 0;
    for (int i = 0; i < 20; i += 2) acc = (acc << 1) + (unsigned long)(p[i] | (p[i + 1] << 8));
    return (unsigned)(((acc & 0x7FFF) + (acc >> 15)) & 0x7FFF);
}

/* Sends one request; reads the reply up to its Ctrl-Z. Returns 0, or -1 when the port is gone
 * or the robot refused the request. */
static int request(int fd, const char *line) {
    char out[128];
    int n = snprintf(out, sizeof out, "%s\n", line);
    if (write(fd, out, (size_t)n) != n) return -1;
    char reply[8192];
    size_t len = 0;
    for (;;) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, 2000) <= 0) return -1;
        ssize_t got = read(fd, reply + len, sizeof reply - 1 - len);
        if (got <= 0) return -1;
        len += (size_t)got;
        if (reply[len - 1] == 0x1A) break;
        if (len >= sizeof reply - 1) len = 0; /* a reply this long is not ours to keep */
    }
    reply[len] = '\0';
    if (strstr(reply, "Error:") || strstr(reply, "Unknown Cmd")) {
        fprintf(stderr, "c-firmware: %s: refused\n", line);
        return -1;
    }
    return 0;
}

static int cmp_int(const void *a, const void *b) { return *(const int *)a - *(const int *)b; }

/* Median valid distance within HALF_WIDTH of angle 0, or -1. */
static int front_mm(const int *scan) {
    int near[2 * HALF_WIDTH + 1], n = 0;
    for (int k = -HALF_WIDTH; k <= HALF_WIDTH; k++) {
        int d = scan[(360 + k) % 360];
        if (d > 0) near[n++] = d;
    }
    if (n < 3) return -1;
    qsort(near, (size_t)n, sizeof near[0], cmp_int);
    return near[n / 2];
}

int main(int argc, char **argv) {
    /* --allow-gaps: a link that drops packets (a scenario's [link]) is expected; count them. */
    int allow_gaps = argc > 1 && strcmp(argv[1], "--allow-gaps") == 0;
    const char *lidar_path = getenv("HILSIM_LIDAR_PORT"), *robot_path = getenv("HILSIM_ROBOT_PORT");
    if (!lidar_path || !robot_path) {
        fprintf(stderr, "c-firmware: HILSIM_LIDAR_PORT and HILSIM_ROBOT_PORT must be set\n");
        return 2;
    }
    int lidar = open_port(lidar_path), robot = open_port(robot_path);
    if (lidar < 0 || robot < 0) {
        fprintf(stderr, "c-firmware: cannot open the ports: %s\n", strerror(errno));
        return 2;
    }
    if (request(robot, "TestMode On") != 0) return 3;

    unsigned char buf[4096 + 22];
    size_t pending = 0;
    int scan[360] = {0}, last_index = -1, packets_in_rev = 0, front = -1;
    unsigned long revolutions = 0, gaps = 0, bad = 0, steps = 0;
    int reached = 0, settled = 0;
    for (;;) {
        ssize_t got = read(lidar, buf + pending, sizeof buf - pending);
        if (got <= 0) break; /* the run is over */
        pending += (size_t)got;
        size_t at = 0;
        while (pending - at >= 22) {
            unsigned char *p = buf + at;
            if (p[0] != 0xFA || p[1] < 0xA0 || p[1] > 0xF9) { at++; continue; }
            if (checksum(p) != (unsigned)(p[20] | (p[21] << 8))) { bad++; at++; continue; }
            int index = p[1] - 0xA0;
            if (last_index >= 0 && index != (last_index + 1) % 90) gaps++;
            if (index == 0 || index != last_index + 1) packets_in_rev = 0;
            last_index = index;
            for (int s = 0; s < 4; s++) {
                const unsigned char *r = p + 4 + 4 * s;
                scan[index * 4 + s] = (r[1] & 0x80) ? 0 : (r[0] | ((r[1] & 0x3F) << 8));
            }
            at += 22;
            if (++packets_in_rev < 90 || index != 89) continue;
            /* A whole revolution. */
            revolutions++;
            front = front_mm(scan);
            if (front < 0) continue;
            if (reached) {
                if (++settled == 2) goto done;
                continue;
            }
            char line[96];
            if (front <= TARGET_MM) {
                reached = 1;
                snprintf(line, sizeof line, "SetMotor LWheelDist 0 RWheelDist 0 Speed 0");
            } else {
                int remaining = front - TARGET_MM;
                int speed = (int)(GAIN * remaining);
                if (speed < MIN_SPEED) speed = MIN_SPEED;
                if (speed > MAX_SPEED) speed = MAX_SPEED;
                steps++;
                snprintf(line, sizeof line, "SetMotor LWheelDist %d RWheelDist %d Speed %d",
                         remaining, remaining, speed);
            }
            fprintf(stderr, "c-firmware: front %d mm: %s\n", front, line);
            if (request(robot, line) != 0) goto done;
        }
        memmove(buf, buf + at, pending - at);
        pending -= at;
    }
done:
    printf("c-firmware: %s; front %d mm after %lu SetMotor steps; revolutions %lu, "
           "index gaps %lu, bad checksums %lu\n",
           reached ? "reached the target" : "did not reach the target", front, steps,
           revolutions, gaps, bad);
    fflush(stdout);
    request(robot, "TestMode Off");
    if (!reached) return 3;
    return gaps && !allow_gaps ? 4 : 0;
}
