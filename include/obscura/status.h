/* obscura status codes: one enum, generated from one X-macro. */
#ifndef OBSCURA_STATUS_H
#define OBSCURA_STATUS_H

#ifdef __cplusplus
extern "C" {
#endif

#define OBS_VERSION "0.1.0"
#define OBS_ERR_LEN 512

/* ---- status ------------------------------------------------------------ */

#define OBS_STATUS_MAP(X)                                                      \
    X(OK, "success")                                                           \
    X(INVALID_ARGUMENT, "invalid argument or parameter")                       \
    X(NO_MEMORY, "out of memory")                                              \
    X(IO, "file could not be opened, read or written")                         \
    X(BAD_FILE, "file is damaged or not in the expected format")               \
    X(UNSUPPORTED, "file uses a feature obscura does not support")             \
    X(MISSING_CHANNEL, "G-buffer lacks a required channel")                    \
    X(TOO_LARGE, "image exceeds the configured size limits")                   \
    X(NO_CAMERA, "no usable camera for the G-buffer")                          \
    X(GL_UNAVAILABLE, "no OpenGL context could be created")                    \
    X(GL_SHADER, "a shader failed to compile or link")                         \
    X(GL_ERROR, "OpenGL reported an error")                                    \
    X(TOO_COSTLY, "the request's work exceeds the configured limit")          \
    X(DEADLINE, "the frame's GL work ran past the configured deadline")       \
    X(CANCELLED, "the work was cancelled")

typedef enum obs_status {
#define OBS__STATUS_ENUM(name, msg) OBS_##name,
    OBS_STATUS_MAP(OBS__STATUS_ENUM)
#undef OBS__STATUS_ENUM
        OBS_STATUS_COUNT
} obs_status;

/* "OK", "MISSING_CHANNEL", ...; never NULL. */
const char *obs_status_name(obs_status s);
/* One-line description of the status class; never NULL. */
const char *obs_status_message(obs_status s);

/* Writes a formatted message into err (if non-NULL) and returns s: the
 * one formatter of every status with its detail, in core and in the
 * units above it. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 3, 4)))
#endif
obs_status obs_status_fail(char err[OBS_ERR_LEN], obs_status s, const char *fmt, ...);

#ifdef __cplusplus
}
#endif

#endif
