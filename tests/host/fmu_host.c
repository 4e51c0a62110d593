/* A minimal FMI 2.0 Co-Simulation host in portable C, to run boomsim's libraries on every platform
 * (Linux x86-64 natively, Windows x64 under wine, Linux aarch64 under qemu-user) and compare the
 * numbers. It loads one or two libraries with dlopen/LoadLibrary, instantiates each with its GUID,
 * sets start values, steps them in order (Gauss-Seidel: each FMU's inputs are read from the others
 * just before its step) and prints the requested outputs with 17 significant digits.
 *
 *   fmu_host STEPS H LIB GUID [LIB GUID] -- OP...
 *     real:I:VR=X     Real start value of FMU I (0 or 1), set in initialisation mode
 *     bool:I:VR=B     Boolean start value (0/1), set before initialisation mode
 *     link:I:VR=J:VR  before each step of FMU I: its input VR gets FMU J's output VR
 *     ramp:I:VR=X,D   before each step of FMU I: its input VR is X + D t
 *     print:I:VR      printed after every 100th step and the last
 *     tol:X           relative tolerance for fmi2SetupExperiment (default: none defined)
 *
 * Exit status: 0 when every call returned fmi2OK, 1 otherwise (the failing call is printed). */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
#define LOAD(path) ((void *)LoadLibraryA(path))
#define SYMBOL(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#else
#include <dlfcn.h>
#define LOAD(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYMBOL(lib, name) dlsym(lib, name)
#endif

typedef void *Component;
typedef unsigned int VR;
typedef int Status; /* fmi2OK = 0 */

typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

typedef struct {
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    Status (*setup)(Component, int, double, double, int, double);
    Status (*enter_init)(Component);
    Status (*exit_init)(Component);
    Status (*set_real)(Component, const VR *, size_t, const double *);
    Status (*get_real)(Component, const VR *, size_t, double *);
    Status (*set_boolean)(Component, const VR *, size_t, const int *);
    Status (*do_step)(Component, double, double, int);
    Status (*terminate)(Component);
    void (*free_instance)(Component);
    Component c;
} Fmu;

enum { MAX_OPS = 64 };
typedef struct {
    char kind; /* 'r' real, 'b' bool, 'l' link, 'm' ramp, 'p' print, 't' tolerance */
    int fmu, src_fmu;
    VR vr, src_vr;
    double value, slope;
} Op;

static void logger(void *env, const char *name, int status, const char *category, const char *format, ...) {
    va_list args;
    (void)env;
    if (status == 0) return; /* only warnings and errors matter here */
    fprintf(stderr, "[%s %d %s] ", name, status, category);
    va_start(args, format);
    vfprintf(stderr, format, args);
    va_end(args);
    fputc('\n', stderr);
}

static void check(Status s, const char *what) {
    if (s != 0) {
        fprintf(stderr, "fmu_host: %s returned status %d\n", what, s);
        exit(1);
    }
}

static void *need(void *lib, const char *name) {
    void *f = SYMBOL(lib, name);
    if (!f) {
        fprintf(stderr, "fmu_host: symbol %s is missing\n", name);
        exit(1);
    }
    return f;
}

static void load(Fmu *f, const char *path, const char *guid, const Callbacks *cb) {
    void *lib = LOAD(path);
    if (!lib) {
        fprintf(stderr, "fmu_host: cannot load %s\n", path);
        exit(1);
    }
    *(void **)&f->instantiate = need(lib, "fmi2Instantiate");
    *(void **)&f->setup = need(lib, "fmi2SetupExperiment");
    *(void **)&f->enter_init = need(lib, "fmi2EnterInitializationMode");
    *(void **)&f->exit_init = need(lib, "fmi2ExitInitializationMode");
    *(void **)&f->set_real = need(lib, "fmi2SetReal");
    *(void **)&f->get_real = need(lib, "fmi2GetReal");
    *(void **)&f->set_boolean = need(lib, "fmi2SetBoolean");
    *(void **)&f->do_step = need(lib, "fmi2DoStep");
    *(void **)&f->terminate = need(lib, "fmi2Terminate");
    *(void **)&f->free_instance = need(lib, "fmi2FreeInstance");
    f->c = f->instantiate("host", 1 /* fmi2CoSimulation */, guid, "", cb, 0, 0);
    if (!f->c) {
        fprintf(stderr, "fmu_host: fmi2Instantiate of %s refused\n", path);
        exit(1);
    }
}

static Op parse(const char *s) {
    Op op = {0};
    unsigned vr = 0, src_vr = 0;
    if (sscanf(s, "real:%d:%u=%lf", &op.fmu, &vr, &op.value) == 3) op.kind = 'r';
    else if (sscanf(s, "bool:%d:%u=%lf", &op.fmu, &vr, &op.value) == 3) op.kind = 'b';
    else if (sscanf(s, "link:%d:%u=%d:%u", &op.fmu, &vr, &op.src_fmu, &src_vr) == 4) op.kind = 'l';
    else if (sscanf(s, "ramp:%d:%u=%lf,%lf", &op.fmu, &vr, &op.value, &op.slope) == 4) op.kind = 'm';
    else if (sscanf(s, "print:%d:%u", &op.fmu, &vr) == 2) op.kind = 'p';
    else if (sscanf(s, "tol:%lf", &op.value) == 1) op.kind = 't';
    else {
        fprintf(stderr, "fmu_host: cannot read \"%s\"\n", s);
        exit(2);
    }
    op.vr = vr;
    op.src_vr = src_vr;
    return op;
}

static void print_outputs(Fmu *fmus, const Op *ops, int n_ops, double t) {
    printf("%.17g", t);
    for (int k = 0; k < n_ops; k++) {
        if (ops[k].kind != 'p') continue;
        double x;
        check(fmus[ops[k].fmu].get_real(fmus[ops[k].fmu].c, &ops[k].vr, 1, &x), "fmi2GetReal");
        printf(" %.17g", x);
    }
    printf("\n");
}

int main(int argc, char **argv) {
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    Fmu fmus[2];
    Op ops[MAX_OPS];
    int n_fmus = 0, n_ops = 0, k = 3;
    if (argc < 6) {
        fprintf(stderr, "usage: fmu_host STEPS H LIB GUID [LIB GUID] -- OP...\n");
        return 2;
    }
    long steps = atol(argv[1]);
    double h = atof(argv[2]);
    for (; k + 1 < argc && strcmp(argv[k], "--") != 0 && n_fmus < 2; k += 2) load(&fmus[n_fmus++], argv[k], argv[k + 1], &cb);
    for (k++; k < argc && n_ops < MAX_OPS; k++) ops[n_ops++] = parse(argv[k]);

    double tolerance = 0.0;
    for (int j = 0; j < n_ops; j++) {
        if (ops[j].kind == 't') tolerance = ops[j].value;
    }
    for (int i = 0; i < n_fmus; i++) {
        for (int j = 0; j < n_ops; j++) {
            if (ops[j].kind == 'b' && ops[j].fmu == i) {
                int b = ops[j].value != 0;
                check(fmus[i].set_boolean(fmus[i].c, &ops[j].vr, 1, &b), "fmi2SetBoolean");
            }
        }
        check(fmus[i].setup(fmus[i].c, tolerance > 0, tolerance, 0.0, 0, 0.0), "fmi2SetupExperiment");
        check(fmus[i].enter_init(fmus[i].c), "fmi2EnterInitializationMode");
        for (int j = 0; j < n_ops; j++) {
            if (ops[j].kind == 'r' && ops[j].fmu == i) check(fmus[i].set_real(fmus[i].c, &ops[j].vr, 1, &ops[j].value), "fmi2SetReal");
        }
        check(fmus[i].exit_init(fmus[i].c), "fmi2ExitInitializationMode");
    }
    for (long n = 0; n < steps; n++) {
        double t = n * h;
        for (int i = 0; i < n_fmus; i++) {
            for (int j = 0; j < n_ops; j++) {
                if (ops[j].fmu != i || (ops[j].kind != 'l' && ops[j].kind != 'm')) continue;
                double x = ops[j].value + ops[j].slope * t;
                if (ops[j].kind == 'l') {
                    Fmu *src = &fmus[ops[j].src_fmu];
                    check(src->get_real(src->c, &ops[j].src_vr, 1, &x), "fmi2GetReal");
                }
                check(fmus[i].set_real(fmus[i].c, &ops[j].vr, 1, &x), "fmi2SetReal");
            }
            check(fmus[i].do_step(fmus[i].c, t, h, 1), "fmi2DoStep");
        }
        if ((n + 1) % 100 == 0 || n + 1 == steps) print_outputs(fmus, ops, n_ops, (n + 1) * h);
    }
    for (int i = 0; i < n_fmus; i++) {
        check(fmus[i].terminate(fmus[i].c), "fmi2Terminate");
        fmus[i].free_instance(fmus[i].c);
    }
    return 0;
}
