/*
 * FrictionMount.fmu, binaries/linux64/FrictionMount.so: a loader in front of
 * pythonfmu's binary, so that importers which are not Python programs (C/C++ tools
 * such as OMSimulator, fmusim, the FMU Compliance Checker, libcosim's `cosim`) can
 * run the FMU without LD_PRELOAD.
 *
 * pythonfmu's binary (shipped next to this one as FrictionMount.pythonfmu.so) calls
 * the Python C API but does not link libpython: in a Python process (fmpy,
 * libcosimpy, PyFMI) the interpreter's symbols are already there; in any other process
 * loading it fails with an undefined symbol. At the first fmi2Instantiate this loader
 *
 *   1. checks whether the process already has Python (Py_IsInitialized visible);
 *   2. if not, picks a libpython: $DRYMOUNT_LIBPYTHON if set (and nothing else),
 *      else the first that works of the path of the Python that built the FMU
 *      (DRYMOUNT_LIBPYTHON_PATH below), the Python found on the host (python3.X on $PATH, its prefix's lib/) and the soname on
 *      the loader's search path. The Python version is the one of the library
 *      actually loaded (Py_GetVersion), not the one the FMU was built with. A
 *      candidate is used only if its prefix holds the standard library of that
 *      version (<prefix>/lib/python3.X/os.py and encodings/): the prefix is
 *      $DRYMOUNT_PYTHONHOME if set (used as given, never searched further), else
 *      $PYTHONHOME if set, else the recorded prefix (for the recorded library),
 *      else the nearest folder above the library file that holds lib/python3.X.
 *      Starting an interpreter without its standard library kills the importer
 *      ("Fatal Python error: init_fs_encoding"), so this is checked before anything
 *      is started. The chosen library is loaded with RTLD_GLOBAL, PYTHONHOME is set
 *      to its prefix, and the interpreter is started here (Py_InitializeEx(0): no
 *      signal handlers) and never finalised. pythonfmu then finds Python running and
 *      leaves it alone; it would otherwise finalise it in a static destructor at
 *      exit, before an importer (OMSimulator) frees its instances in its own exit
 *      handlers, and that late fmi2FreeInstance crashed the host (exit 139);
 *   3. loads FrictionMount.pythonfmu.so from its own directory and forwards every
 *      FMI call to it.
 *
 * Failures are reported through the importer's logger (category "drymount", every
 * candidate with the reason it was refused, and the variables DRYMOUNT_LIBPYTHON and
 * DRYMOUNT_PYTHONHOME that fix it) and make fmi2Instantiate return NULL.
 *
 * Rejected calls: pythonfmu 0.7.0 turns every Python exception into fmi2Fatal and
 * drops the instance. The model (fmu_src/friction_mount.py) therefore rejects a call
 * that breaks the FMI call-order rules (docs/fmu.md) without raising: it logs the
 * reason and calls drymount_reject_call() below, and the forwarder returns
 * fmi2Error for that call; the instance stays usable.
 *
 * glibc floor: the library asks for no symbol version above GLIBC_2.14 (the dl*
 * and pthread_key/once functions are bound to their GLIBC_2.2.5 versions below, and
 * libdl.so.2 / libpthread.so.0 are linked explicitly, where glibc < 2.34 keeps
 * them), so it loads wherever pythonfmu's own binary does (GLIBC_2.32): RHEL 8,
 * Debian 11, Ubuntu 20.04. tests/test_fmu_loader.py reads the versions.
 *
 * The build (fmu_build/builder.py) compiles this
 * file with the paths of the building Python:
 *   cc -shared -fPIC -O2 -fvisibility=hidden -DDRYMOUNT_LIBPYTHON_PATH=... \
 *      -DDRYMOUNT_LIBPYTHON_SONAME=... -DDRYMOUNT_PYTHONHOME=... \
 *      -Wl,--no-as-needed -l:libdl.so.2 -l:libpthread.so.0
 * Self-contained: the FMI 2.0 types are declared as in fmi2TypesPlatform.h and
 * fmi2FunctionTypes.h.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <unistd.h>

/* The oldest versions of the functions glibc 2.34 moved from libdl and libpthread
 * into libc (x86_64: GLIBC_2.2.5); an older glibc resolves them in libdl.so.2 and
 * libpthread.so.0, which the build links. */
#if defined(__x86_64__) && defined(__GLIBC__)
#define OLD_SYMBOL(name) __asm__(".symver " #name "," #name "@GLIBC_2.2.5");
OLD_SYMBOL(dlopen)
OLD_SYMBOL(dlsym)
OLD_SYMBOL(dladdr)
OLD_SYMBOL(dlerror)
OLD_SYMBOL(dlclose)
OLD_SYMBOL(pthread_key_create)
OLD_SYMBOL(pthread_key_delete)
OLD_SYMBOL(pthread_getspecific)
OLD_SYMBOL(pthread_setspecific)
OLD_SYMBOL(pthread_once)
#endif

#ifndef DRYMOUNT_LIBPYTHON_PATH
#define DRYMOUNT_LIBPYTHON_PATH ""
#endif
#ifndef DRYMOUNT_LIBPYTHON_SONAME
#define DRYMOUNT_LIBPYTHON_SONAME ""
#endif
#ifndef DRYMOUNT_PYTHONHOME
#define DRYMOUNT_PYTHONHOME ""
#endif
#define REAL_BINARY "FrictionMount.pythonfmu.so"
#define EXPORT __attribute__((visibility("default")))

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum {
    fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated
} fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef const fmi2ValueReference *VRs;

/* one X(name, return type, parameter list, argument list) per forwarded function */
#define FMI2_FORWARDED(X) \
    X(fmi2SetDebugLogging, fmi2Status, (fmi2Component c, fmi2Boolean on, size_t n, \
      const fmi2String cat[]), (c, on, n, cat)) \
    X(fmi2SetupExperiment, fmi2Status, (fmi2Component c, fmi2Boolean tol_def, \
      fmi2Real tol, fmi2Real t0, fmi2Boolean stop_def, fmi2Real t1), \
      (c, tol_def, tol, t0, stop_def, t1)) \
    X(fmi2EnterInitializationMode, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2ExitInitializationMode, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2Terminate, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2Reset, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2GetReal, fmi2Status, (fmi2Component c, VRs vr, size_t n, fmi2Real v[]), \
      (c, vr, n, v)) \
    X(fmi2GetInteger, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2Integer v[]), (c, vr, n, v)) \
    X(fmi2GetBoolean, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2Boolean v[]), (c, vr, n, v)) \
    X(fmi2GetString, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2String v[]), (c, vr, n, v)) \
    X(fmi2SetReal, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Real v[]), (c, vr, n, v)) \
    X(fmi2SetInteger, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer v[]), (c, vr, n, v)) \
    X(fmi2SetBoolean, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Boolean v[]), (c, vr, n, v)) \
    X(fmi2SetString, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2String v[]), (c, vr, n, v)) \
    X(fmi2GetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(fmi2SetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate s), (c, s)) \
    X(fmi2FreeFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(fmi2SerializedFMUstateSize, fmi2Status, (fmi2Component c, fmi2FMUstate s, \
      size_t *size), (c, s, size)) \
    X(fmi2SerializeFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate s, \
      fmi2Byte b[], size_t size), (c, s, b, size)) \
    X(fmi2DeSerializeFMUstate, fmi2Status, (fmi2Component c, const fmi2Byte b[], \
      size_t size, fmi2FMUstate *s), (c, b, size, s)) \
    X(fmi2GetDirectionalDerivative, fmi2Status, (fmi2Component c, VRs unk, size_t nu, \
      VRs known, size_t nk, const fmi2Real dv_known[], fmi2Real dv_unknown[]), \
      (c, unk, nu, known, nk, dv_known, dv_unknown)) \
    X(fmi2SetRealInputDerivatives, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer order[], const fmi2Real v[]), (c, vr, n, order, v)) \
    X(fmi2GetRealOutputDerivatives, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer order[], fmi2Real v[]), (c, vr, n, order, v)) \
    X(fmi2DoStep, fmi2Status, (fmi2Component c, fmi2Real t, fmi2Real h, \
      fmi2Boolean no_prior), (c, t, h, no_prior)) \
    X(fmi2CancelStep, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2GetStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Status *v), (c, k, v)) \
    X(fmi2GetRealStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Real *v), (c, k, v)) \
    X(fmi2GetIntegerStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Integer *v), (c, k, v)) \
    X(fmi2GetBooleanStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Boolean *v), (c, k, v)) \
    X(fmi2GetStringStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2String *v), (c, k, v))

typedef fmi2Component (*Instantiate_t)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions *, fmi2Boolean,
                                       fmi2Boolean);
typedef void (*FreeInstance_t)(fmi2Component);
static Instantiate_t real_Instantiate;
static FreeInstance_t real_FreeInstance;

#define DECLARE_POINTER(name, ret, params, args) static ret(*real_##name) params;
FMI2_FORWARDED(DECLARE_POINTER)

static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;
static int loaded;            /* 1: every real_* pointer is set */
static char load_error[8192]; /* why loading failed (kept for later instances) */

/* "3.11" from the soname "libpython3.11.so.1.0" (abiflags such as "d" dropped). */
static void python_version(char *out, size_t size) {
    const char *p = strstr(DRYMOUNT_LIBPYTHON_SONAME, "libpython");
    size_t n = 0;
    if (p != NULL) {
        p += strlen("libpython");
        while (p[n] != '\0' && (p[n] == '.' || (p[n] >= '0' && p[n] <= '9')) &&
               strncmp(p + n, ".so", 3) != 0)
            ++n;
    }
    snprintf(out, size, "%.*s", (int)n, p ? p : "");
}

/* 1 if path opens and is not a folder (open only: stat is stat@GLIBC_2.33). */
/* "3.12" from the library h: Py_GetVersion() ("3.12.1 (main, ...)"), callable before
 * the interpreter starts; 0 on success. */
static int loaded_version(void *h, char *out, size_t size) {
    const char *(*get_version)(void);
    *(void **)(&get_version) = dlsym(h, "Py_GetVersion");
    const char *v = get_version ? get_version() : NULL;
    size_t n = 0;
    int dots = 0;
    if (v == NULL)
        return -1;
    for (; (v[n] >= '0' && v[n] <= '9') || (v[n] == '.' && dots == 0); ++n)
        dots += v[n] == '.';
    if (dots != 1 || n < 3 || v[n - 1] == '.')
        return -1;
    snprintf(out, size, "%.*s", (int)n, v);
    return 0;
}

static int is_file(const char *path) {
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return 0;
    close(fd);
    fd = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        close(fd);
        return 0;
    }
    return errno == ENOTDIR;
}

/* 1 if <home>/lib/python<ver> holds the standard library's os.py and encodings. */
static int has_stdlib(const char *home, const char *ver) {
    char path[4200];
    if (home == NULL || home[0] == '\0')
        return 0;
    snprintf(path, sizeof path, "%s/lib/python%s/os.py", home, ver);
    if (!is_file(path))
        return 0;
    snprintf(path, sizeof path, "%s/lib/python%s/encodings/__init__.py", home, ver);
    return is_file(path);
}

/* The nearest folder above the library file that holds the standard library. */
static int prefix_above(const char *lib, const char *ver, char *out, size_t size) {
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", lib);
    char *slash;
    while ((slash = strrchr(dir, '/')) != NULL) {
        *slash = '\0';
        if (has_stdlib(dir[0] ? dir : "/", ver)) {
            snprintf(out, size, "%s", dir[0] ? dir : "/");
            return 1;
        }
    }
    return 0;
}

/* python<ver> on $PATH: its library <prefix>/lib/<soname> and prefix. */
static int host_python(const char *ver, char *lib, size_t lib_size, char *home,
                       size_t home_size) {
    const char *path = getenv("PATH");
    char buf[8192], exe[4200], real[4096];
    if (path == NULL || DRYMOUNT_LIBPYTHON_SONAME[0] == '\0')
        return 0;
    snprintf(buf, sizeof buf, "%s", path);
    for (char *save = NULL, *dir = strtok_r(buf, ":", &save); dir != NULL;
         dir = strtok_r(NULL, ":", &save)) {
        snprintf(exe, sizeof exe, "%s/python%s", dir[0] ? dir : ".", ver);
        if (access(exe, X_OK) != 0 || realpath(exe, real) == NULL)
            continue;
        char *slash = strrchr(real, '/'); /* <prefix>/bin/python3.X */
        if (slash == NULL)
            continue;
        *slash = '\0';
        slash = strrchr(real, '/');
        if (slash == NULL)
            continue;
        *slash = '\0';
        snprintf(lib, lib_size, "%s/lib/%s", real[0] ? real : "", DRYMOUNT_LIBPYTHON_SONAME);
        snprintf(home, home_size, "%s", real[0] ? real : "/");
        if (is_file(lib))
            return 1;
    }
    return 0;
}

static void note(char *tried, size_t size, const char *lib, const char *why) {
    size_t used = strlen(tried);
    snprintf(tried + used, size - used, "%s%s (%s)", used ? "; " : "", lib, why);
}

/* ``home`` if it is the prefix of Python ``ver``, else NULL with the reason (naming
 * the variable ``var`` that gave it) in why. */
static const char *as_given(const char *var, const char *home, const char *ver,
                            char *why, size_t size) {
    if (has_stdlib(home, ver))
        return home;
    snprintf(why, size, "%s=%s holds no lib/python%s/os.py and encodings/ (the library "
             "is Python %s)", var, home, ver, ver);
    return NULL;
}

/* Start the interpreter of the library just loaded and release its lock: pythonfmu
 * then finds Python running and never finalises it (see the top of this file). */
static int start_python(void *h) {
    void (*init)(int);
    void *(*save_thread)(void);
    int (*is_initialized)(void);
    *(void **)(&init) = dlsym(h, "Py_InitializeEx");
    *(void **)(&save_thread) = dlsym(h, "PyEval_SaveThread");
    *(void **)(&is_initialized) = dlsym(h, "Py_IsInitialized");
    if (init == NULL || save_thread == NULL || is_initialized == NULL)
        return -1;
    init(0);
    if (!is_initialized())
        return -1;
    save_thread();
    return 0;
}

/* Try one candidate library with the prefix hint ``home`` (``home_var`` names where
 * the hint came from; the hint of a variable is used as given); 0 when loaded. */
static int try_libpython(const char *lib, const char *home, const char *home_var,
                         char *tried, size_t size) {
    char found[4096] = "", why[4400] = "", ver[32];
    const char *user_home = getenv("PYTHONHOME");
    int by_path = strchr(lib, '/') != NULL;
    if (by_path && !is_file(lib)) {
        note(tried, size, lib, "no such file");
        return -1;
    }
    void *h = dlopen(lib, RTLD_NOW | RTLD_GLOBAL);
    if (h == NULL) {
        note(tried, size, lib, dlerror());
        return -1;
    }
    Dl_info info;
    void *sym = dlsym(h, "Py_IsInitialized");
    const char *file = (sym && dladdr(sym, &info) && info.dli_fname) ? info.dli_fname : lib;
    const char *use = NULL;
    if (loaded_version(h, ver, sizeof ver) != 0)
        snprintf(why, sizeof why, "not a CPython library: no Py_GetVersion");
    else if (home_var != NULL && home[0] != '\0')
        use = as_given(home_var, home, ver, why, sizeof why);
    else if (user_home != NULL && user_home[0] != '\0')
        use = as_given("PYTHONHOME", user_home, ver, why, sizeof why);
    else if (has_stdlib(home, ver))
        use = home;
    else if (prefix_above(file, ver, found, sizeof found))
        use = found;
    else
        snprintf(why, sizeof why, "no standard library lib/python%s/os.py under %s%s%s",
                 ver, home && home[0] ? home : "", home && home[0] ? " nor above " : "",
                 file);
    if (use != NULL) {
        setenv("PYTHONHOME", use, 1);
        if (start_python(h) == 0)
            return 0;
        snprintf(why, sizeof why, "Python %s with PYTHONHOME=%s did not start", ver, use);
    }
    dlclose(h); /* nothing was started */
    note(tried, size, lib, why);
    return -1;
}

/* The candidates when DRYMOUNT_LIBPYTHON is not set; 0 when one is loaded. */
static int try_defaults(const char *ver, const char *env_home, char *tried,
                        size_t size) {
    char host_lib[4400], host_home[4096];
    const char *var = env_home ? "DRYMOUNT_PYTHONHOME" : NULL;
    if (DRYMOUNT_LIBPYTHON_PATH[0] != '\0' &&
        try_libpython(DRYMOUNT_LIBPYTHON_PATH, env_home ? env_home : DRYMOUNT_PYTHONHOME,
                      var, tried, size) == 0)
        return 0;
    if (host_python(ver, host_lib, sizeof host_lib, host_home, sizeof host_home) &&
        strcmp(host_lib, DRYMOUNT_LIBPYTHON_PATH) != 0 &&
        try_libpython(host_lib, env_home ? env_home : host_home, var, tried, size) == 0)
        return 0;
    if (DRYMOUNT_LIBPYTHON_SONAME[0] != '\0' &&
        try_libpython(DRYMOUNT_LIBPYTHON_SONAME, env_home ? env_home : "", var, tried,
                      size) == 0)
        return 0;
    return -1;
}

static int load_libpython(void) {
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized") != NULL)
        return 0; /* a Python process (or LD_PRELOAD): nothing to do */
    char ver[32], tried[6000] = "";
    python_version(ver, sizeof ver);
    const char *env_lib = getenv("DRYMOUNT_LIBPYTHON");
    const char *env_home = getenv("DRYMOUNT_PYTHONHOME");
    if (env_home != NULL && env_home[0] == '\0')
        env_home = NULL;
    if (env_lib != NULL && env_lib[0] != '\0') { /* the user's choice, and no other */
        if (try_libpython(env_lib, env_home ? env_home : "",
                          env_home ? "DRYMOUNT_PYTHONHOME" : NULL, tried,
                          sizeof tried) == 0)
            return 0;
    } else if (try_defaults(ver, env_home, tried, sizeof tried) == 0) {
        return 0;
    }
    snprintf(load_error, sizeof load_error,
             "cannot start Python %s for the FMU (tried: %s). Set DRYMOUNT_LIBPYTHON to "
             "the libpython3.X.so of a CPython 3 built with --enable-shared (the FMU was "
             "built with %s) and DRYMOUNT_PYTHONHOME to its prefix (the folder holding "
             "lib/python3.X/os.py), or LD_PRELOAD that library with PYTHONHOME set "
             "(documentation/externalDependencies.txt)",
             ver, tried[0] ? tried : "nothing", ver);
    return -1;
}

static int load_real_binary(void) {
    Dl_info info;
    if (dladdr((void *)&load_real_binary, &info) == 0 || info.dli_fname == NULL) {
        snprintf(load_error, sizeof load_error, "cannot locate the FMU's binary directory");
        return -1;
    }
    char path[4096];
    const char *slash = strrchr(info.dli_fname, '/');
    int dir_len = slash ? (int)(slash - info.dli_fname) : 1;
    const char *dir = slash ? info.dli_fname : ".";
    snprintf(path, sizeof path, "%.*s/%s", dir_len, dir, REAL_BINARY);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (h == NULL) {
        snprintf(load_error, sizeof load_error, "cannot load %s: %s", path, dlerror());
        return -1;
    }
    real_Instantiate = (Instantiate_t)dlsym(h, "fmi2Instantiate");
    real_FreeInstance = (FreeInstance_t)dlsym(h, "fmi2FreeInstance");
    int missing = real_Instantiate == NULL || real_FreeInstance == NULL;
#define RESOLVE(name, ret, params, args) \
    *(void **)(&real_##name) = dlsym(h, #name); \
    missing |= real_##name == NULL;
    FMI2_FORWARDED(RESOLVE)
    if (missing) {
        snprintf(load_error, sizeof load_error, "%s lacks FMI 2.0 functions", path);
        return -1;
    }
    return 0;
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

static void refuse(const fmi2CallbackFunctions *cb, fmi2String name, const char *why) {
    if (cb != NULL && cb->logger != NULL)
        cb->logger(cb->componentEnvironment, name, fmi2Error, "drymount", "%s", why);
    else
        fprintf(stderr, "FrictionMount: %s\n", why);
}

static int hex_digit(char c) {
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* The folder a "file:" resource URI names, every %XX decoded (RFC 3986, RFC 8089:
 * file:///path, file://localhost/path, file:/path), into out; 0 on success, else -1
 * with the reason in why. */
static int uri_to_path(const char *uri, char *out, size_t size, char *why, size_t wsize) {
    const char *p = uri;
    size_t n = 0;
    if (strncmp(p, "file:", 5) != 0) {
        snprintf(why, wsize, "fmi2Instantiate: fmuResourceLocation must be a file: URI, "
                 "got \"%.300s\"", uri);
        return -1;
    }
    p += 5;
    if (strncmp(p, "//localhost/", 12) == 0)
        p += 11;
    else if (strncmp(p, "///", 3) == 0)
        p += 2;
    else if (p[0] == '/' && p[1] == '/') {
        snprintf(why, wsize, "fmi2Instantiate: fmuResourceLocation names a remote host "
                 "(\"%.300s\"); only local folders are supported", uri);
        return -1;
    }
    for (; *p != '\0'; ++p) {
        int c = (unsigned char)*p;
        if (c == '%') {
            int hi = hex_digit(p[1]), lo = hi < 0 ? -1 : hex_digit(p[2]);
            c = hi < 0 || lo < 0 ? -1 : hi * 16 + lo;
            if (c <= 0) {
                snprintf(why, wsize, "fmi2Instantiate: fmuResourceLocation has an invalid "
                         "percent escape at \"%.8s\" (\"%.300s\")", p, uri);
                return -1;
            }
            p += 2;
        }
        if (n + 1 >= size) {
            snprintf(why, wsize, "fmi2Instantiate: fmuResourceLocation is too long "
                     "(%zu characters)", strlen(uri));
            return -1;
        }
        out[n++] = (char)c;
    }
    out[n] = '\0';
    return 0;
}

/* pythonfmu 0.7.0 (fmi2.cpp) turns the URI into a path by replacing "%20" with a space
 * and dropping "file://", nothing else: any other escape (non-ASCII letters, # ; % ")
 * left a folder that does not exist, and its loader then crashed the host (a NULL
 * class without a Python exception). Hand it "file://" + the decoded path; a path
 * holding "%20" itself (a folder named "pct%20x") cannot pass that replacement, so it
 * goes as /proc/self/fd/<fd of the FMU folder>/resources (the descriptor stays open:
 * the path is on sys.path for the life of the process). */
static int pythonfmu_location(const char *uri, char *out, size_t size, char *why,
                              size_t wsize) {
    char path[4096], probe[4200];
    if (uri == NULL) {
        snprintf(why, wsize, "fmi2Instantiate: fmuResourceLocation is NULL");
        return -1;
    }
    if (uri_to_path(uri, path, sizeof path, why, wsize) != 0)
        return -1;
    size_t len = strlen(path);
    while (len > 1 && path[len - 1] == '/')
        path[--len] = '\0';
    snprintf(probe, sizeof probe, "%s/slavemodule.txt", path);
    if (!is_file(probe)) {
        snprintf(why, wsize, "fmi2Instantiate: no resources/slavemodule.txt in the folder "
                 "fmuResourceLocation names (\"%.1000s\" decoded to \"%.1000s\"): is the "
                 "FMU unzipped there?", uri, path);
        return -1;
    }
    if (strstr(path, "%20") == NULL) {
        snprintf(out, size, "file://%s", path);
        return 0;
    }
    char *slash = strrchr(path, '/');
    if (slash == NULL || strcmp(slash, "/resources") != 0) {
        snprintf(why, wsize, "fmi2Instantiate: a resource folder whose path holds \"%%20\" "
                 "must be the FMU's resources/ folder, got \"%.1000s\"", path);
        return -1;
    }
    *slash = '\0';
    static pthread_mutex_t fd_lock = PTHREAD_MUTEX_INITIALIZER;
    static char fd_path[4096]; /* the last folder opened, and its descriptor: */
    static int fd_open = -1;   /* one descriptor per folder, not per instance */
    pthread_mutex_lock(&fd_lock);
    if (fd_open < 0 || strcmp(fd_path, path) != 0) {
        int fresh = open(path[0] ? path : "/", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (fresh >= 0) {
            fd_open = fresh;
            snprintf(fd_path, sizeof fd_path, "%s", path);
        }
    }
    int fd = strcmp(fd_path, path) == 0 ? fd_open : -1;
    pthread_mutex_unlock(&fd_lock);
    if (fd < 0) {
        snprintf(why, wsize, "fmi2Instantiate: cannot open the FMU folder \"%.1000s\"",
                 path);
        return -1;
    }
    snprintf(out, size, "file:///proc/self/fd/%d/resources", fd);
    return 0;
}

#ifndef DRYMOUNT_GUID
#define DRYMOUNT_GUID ""
#endif

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String resources,
                                     const fmi2CallbackFunctions *cb, fmi2Boolean visible,
                                     fmi2Boolean logging) {
    char location[4400], why[2400];
    if (pythonfmu_location(resources, location, sizeof location, why, sizeof why) != 0) {
        refuse(cb, name, why);
        return NULL;
    }
    pthread_mutex_lock(&load_lock);
    if (!loaded && load_error[0] == '\0' && load_libpython() == 0 &&
        load_real_binary() == 0)
        loaded = 1;
    pthread_mutex_unlock(&load_lock);
    if (!loaded) {
        refuse(cb, name, load_error);
        return NULL;
    }
    if (DRYMOUNT_GUID[0] != '\0' && (guid == NULL || strcmp(guid, DRYMOUNT_GUID) != 0)) {
        snprintf(why, sizeof why, "fmi2Instantiate: the GUID \"%.100s\" does not match "
                 "this FMU's \"%s\" (modelDescription.xml)", guid ? guid : "(null)",
                 DRYMOUNT_GUID);
        refuse(cb, name, why);
        return NULL;
    }
    return real_Instantiate(name, type, guid, location, cb, visible, logging);
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    if (loaded && c != NULL)
        real_FreeInstance(c);
}

/* Set by the model during a call it rejects (see the top of this file); per thread,
 * as the model runs in the importer's calling thread. A pthread key rather than
 * __thread: no dynamic TLS block in a library the importer may dlclose. */
static pthread_key_t rejected_key;
static pthread_once_t rejected_once = PTHREAD_ONCE_INIT;
static int rejected_ready;

static void make_rejected_key(void) {
    rejected_ready = pthread_key_create(&rejected_key, NULL) == 0;
}

EXPORT void drymount_reject_call(void) {
    pthread_once(&rejected_once, make_rejected_key);
    if (rejected_ready)
        pthread_setspecific(rejected_key, (void *)1);
}

/* 1 if the model rejected the call this thread is making; clears the mark. */
static int take_rejected(void) {
    pthread_once(&rejected_once, make_rejected_key);
    if (!rejected_ready || pthread_getspecific(rejected_key) == NULL)
        return 0;
    pthread_setspecific(rejected_key, NULL);
    return 1;
}

__attribute__((destructor)) static void drop_rejected_key(void) {
    if (rejected_ready)
        pthread_key_delete(rejected_key);
}

/* Every other function: forward (only reachable with an instance, i.e. after a
 * successful load); a call the model rejected returns fmi2Error. */
#define DEFINE_FORWARD(name, ret, params, args) \
    EXPORT ret name params { \
        if (!loaded) \
            return fmi2Error; \
        take_rejected(); \
        ret status_ = real_##name args; \
        if (take_rejected() && status_ < fmi2Error) \
            status_ = fmi2Error; \
        return status_; \
    }
FMI2_FORWARDED(DEFINE_FORWARD)
