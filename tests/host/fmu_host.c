/* A minimal FMI 2.0 / FMI 3.0 Co-Simulation host in portable C, to run boomsim's libraries on every
 * platform (Linux x86-64 natively, Windows x64 under wine, Linux aarch64 under qemu-user) and
 * compare the numbers. It loads one or two libraries with dlopen/LoadLibrary, instantiates each with
 * its GUID (FMI 2.0) or instantiationToken (FMI 3.0), sets start values, steps them in order
 * (Gauss-Seidel: each FMU's inputs are read from the others just before its step) and prints the
 * requested outputs with 17 significant digits (a double round-trips exactly).
 *
 *   fmu_host [--fmi3] STEPS H LIB GUID [LIB GUID] -- OP...
 *     --fmi3          use the FMI 3.0 entry points (fmi3InstantiateCoSimulation ... fmi3DoStep);
 *                     the scenario logic below is the same for both versions: only the small
 *                     wrappers fmu_* call one version's functions or the other's
 *     real:I:VR=X     Real start value of FMU I (0 or 1), set in initialisation mode
 *     bool:I:VR=B     Boolean start value (0/1), set before initialisation mode
 *     link:I:VR=J:VR  before each step of FMU I: its input VR gets FMU J's output VR
 *     ramp:I:VR=X,D   before each step of FMU I: its input VR is X + D t
 *     print:I:VR      printed after every 100th step and the last
 *     tol:X           relative tolerance (fmi2SetupExperiment / fmi3EnterInitializationMode;
 *                     default: none defined)
 *     clock:I:VR      (--fmi3) FMU I has the input Clock VR with a constant interval, which must be H:
 *                     it is instantiated with eventModeUsed (FMI 3.0, 2.3.1), leaves initialisation
 *                     in Event Mode (fmi3UpdateDiscreteStates, fmi3EnterStepMode), and after each of
 *                     its steps activates the Clock (fmi3EnterEventMode, fmi3SetClock, its link and
 *                     ramp inputs at the step's end, its printed outputs read, fmi3UpdateDiscreteStates,
 *                     fmi3EnterStepMode): FMI 3.0, 2.2.8 and 2.3.5; its clocked outputs are printed
 *                     as read at the last activation
 *     early:I         (--fmi3) FMU I is instantiated with eventModeUsed and earlyReturnAllowed: a step that
 *                     returns early continues from lastSuccessfulTime to the step's end, after Event Mode
 *                     (fmi3EnterEventMode, fmi3UpdateDiscreteStates, fmi3EnterStepMode) where the FMU asks
 *                     for it (eventHandlingNeeded); each early return is written to stderr as
 *                     "fmu_host: early return at T" (FMI 3.0, 4.2.3)
 *     intermediate:I:VR  (--fmi3) FMU I is instantiated with an intermediateUpdate callback and VR as its
 *                     requiredIntermediateVariables; VR's ramp op (ramp:I:VR=X,D) is then also set in the
 *                     callback wherever it requests inputs, to X + D t at its intermediateUpdateTime t
 *                     (FMI 3.0, 4.2.3: the input linear over a step, as FMI 2.0's input derivative)
 *
 * Exit status: 0 when every call returned OK (fmi2OK = fmi3OK = 0), 1 otherwise (the failing call
 * is printed), 2 for bad arguments. */
#include <stdarg.h>
#include <stdbool.h>
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
typedef int Status; /* fmi2OK = fmi3OK = 0 */

typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *environment;
} Callbacks;

/* FMI 3.0's logger: not variadic, no instance name (fmi3LogMessageCallback). */
typedef void (*Logger3)(void *, Status, const char *, const char *);

typedef struct {
    int fmi3; /* 0: the fmi2 functions below, 1: the fmi3 ones */
    const char *path;
    /* FMI 2.0 */
    Component (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    Status (*setup)(Component, int, double, double, int, double);
    Status (*enter_init)(Component);
    Status (*set_real)(Component, const VR *, size_t, const double *);
    Status (*get_real)(Component, const VR *, size_t, double *);
    Status (*set_boolean)(Component, const VR *, size_t, const int *);
    Status (*do_step)(Component, double, double, int);
    /* FMI 3.0 */
    Component (*instantiate3)(const char *, const char *, const char *, bool, bool, bool, bool, const VR *, size_t,
                              void *, Logger3, void *);
    Status (*enter_init3)(Component, bool, double, double, bool, double);
    Status (*set_float64)(Component, const VR *, size_t, const double *, size_t);
    Status (*get_float64)(Component, const VR *, size_t, double *, size_t);
    Status (*set_boolean3)(Component, const VR *, size_t, const bool *, size_t);
    Status (*do_step3)(Component, double, double, bool, bool *, bool *, bool *, double *);
    Status (*enter_event_mode3)(Component);
    Status (*enter_step_mode3)(Component);
    Status (*set_clock3)(Component, const VR *, size_t, const bool *);
    Status (*update_discrete_states3)(Component, bool *, bool *, bool *, bool *, bool *, double *);
    Status (*get_interval3)(Component, const VR *, size_t, double *, int *);
    int clocked; /* clock:I:VR given for this FMU */
    VR clock;
    int early; /* early:I given for this FMU */
    int intermediate; /* intermediate:I:VR given for this FMU: VR on the line X + D t */
    VR intermediate_vr;
    double line_x, line_d;
    /* both (the same signatures) */
    Status (*exit_init)(Component);
    Status (*terminate)(Component);
    void (*free_instance)(Component);
    Component c;
} Fmu;

enum { MAX_OPS = 64 };
typedef struct {
    char kind; /* 'r' real, 'b' bool, 'l' link, 'm' ramp, 'p' print, 't' tolerance, 'c' clock, 'e' early,
                  'i' intermediate */
    int fmu, src_fmu;
    VR vr, src_vr;
    double value, slope;
    double read; /* a print op of a clocked FMU: the value read at the last activation */
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

/* The FMI 3.0 instance environment is the Fmu. */
static void logger3(void *env, Status status, const char *category, const char *message) {
    if (status == 0) return;
    fprintf(stderr, "[%s %d %s] %s\n", ((Fmu *)env)->path, status, category, message);
}

static void check(Status s, const char *what) {
    if (s != 0) {
        fprintf(stderr, "fmu_host: %s returned status %d\n", what, s);
        exit(1);
    }
}

/* fmi3IntermediateUpdateCallback: where inputs are requested, the required input on its line at t;
 * never an early return. */
static void intermediate_update(void *env, double t, bool set_requested, bool get_allowed, bool finished,
                                bool can_return_early, bool *early_return_requested, double *early_return_time) {
    Fmu *f = (Fmu *)env;
    (void)get_allowed, (void)finished, (void)can_return_early, (void)early_return_time;
    *early_return_requested = false;
    if (set_requested) {
        double x = f->line_x + f->line_d * t;
        check(f->set_float64(f->c, &f->intermediate_vr, 1, &x, 1), "fmi3SetFloat64 in intermediate update");
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

static void load(Fmu *f, int fmi3, const char *path, const char *guid, const Callbacks *cb) {
    if (f->clocked && !fmi3) {
        fprintf(stderr, "fmu_host: clock: needs --fmi3 (FMI 2.0 has no Clocks)\n");
        exit(2);
    }
    void *lib = LOAD(path);
    if (!lib) {
        fprintf(stderr, "fmu_host: cannot load %s\n", path);
        exit(1);
    }
    f->fmi3 = fmi3;
    f->path = path;
    const char *v = fmi3 ? "fmi3" : "fmi2";
    char name[64];
#define NEED(field, suffix) (snprintf(name, sizeof name, "%s%s", v, suffix), *(void **)&f->field = need(lib, name))
    NEED(exit_init, "ExitInitializationMode");
    NEED(terminate, "Terminate");
    NEED(free_instance, "FreeInstance");
    if (fmi3) {
        NEED(instantiate3, "InstantiateCoSimulation");
        NEED(enter_init3, "EnterInitializationMode");
        NEED(set_float64, "SetFloat64");
        NEED(get_float64, "GetFloat64");
        NEED(set_boolean3, "SetBoolean");
        NEED(do_step3, "DoStep");
        NEED(enter_event_mode3, "EnterEventMode");
        NEED(enter_step_mode3, "EnterStepMode");
        NEED(set_clock3, "SetClock");
        NEED(update_discrete_states3, "UpdateDiscreteStates");
        NEED(get_interval3, "GetIntervalDecimal");
        /* event mode for an FMU with a Clock or early:I, early return for the latter; the
         * intermediate update for an FMU with intermediate:I:VR; the environment is the Fmu */
        void *callback = f->intermediate ? (void *)intermediate_update : NULL;
        f->c = f->instantiate3("host", guid, NULL, false, false, f->clocked || f->early, f->early, &f->intermediate_vr,
                               (size_t)f->intermediate, f, logger3, callback);
    } else {
        NEED(instantiate, "Instantiate");
        NEED(setup, "SetupExperiment");
        NEED(enter_init, "EnterInitializationMode");
        NEED(set_real, "SetReal");
        NEED(get_real, "GetReal");
        NEED(set_boolean, "SetBoolean");
        NEED(do_step, "DoStep");
        f->c = f->instantiate("host", 1 /* fmi2CoSimulation */, guid, "", cb, 0, 0);
    }
#undef NEED
    if (!f->c) {
        fprintf(stderr, "fmu_host: %sInstantiate%s of %s refused\n", v, fmi3 ? "CoSimulation" : "", path);
        exit(1);
    }
}

/* The version-neutral calls main() makes; each checks the status and names the function. */
static void fmu_enter_init(Fmu *f, double tolerance) {
    if (f->fmi3) {
        check(f->enter_init3(f->c, tolerance > 0, tolerance, 0.0, false, 0.0), "fmi3EnterInitializationMode");
        return;
    }
    check(f->setup(f->c, tolerance > 0, tolerance, 0.0, 0, 0.0), "fmi2SetupExperiment");
    check(f->enter_init(f->c), "fmi2EnterInitializationMode");
}

static void fmu_exit_init(Fmu *f) { check(f->exit_init(f->c), f->fmi3 ? "fmi3ExitInitializationMode" : "fmi2ExitInitializationMode"); }

static void fmu_set_real(Fmu *f, VR vr, double x) {
    if (f->fmi3) check(f->set_float64(f->c, &vr, 1, &x, 1), "fmi3SetFloat64");
    else check(f->set_real(f->c, &vr, 1, &x), "fmi2SetReal");
}

static double fmu_get_real(Fmu *f, VR vr) {
    double x;
    if (f->fmi3) check(f->get_float64(f->c, &vr, 1, &x, 1), "fmi3GetFloat64");
    else check(f->get_real(f->c, &vr, 1, &x), "fmi2GetReal");
    return x;
}

static void fmu_set_boolean(Fmu *f, VR vr, int b) {
    bool b3 = b != 0;
    if (f->fmi3) check(f->set_boolean3(f->c, &vr, 1, &b3, 1), "fmi3SetBoolean");
    else check(f->set_boolean(f->c, &vr, 1, &b), "fmi2SetBoolean");
}

static void fmu_update_discrete_states(Fmu *f) {
    bool need_update, terminate, nominals_changed, values_changed, next_defined;
    double next;
    check(f->update_discrete_states3(f->c, &need_update, &terminate, &nominals_changed, &values_changed,
                                     &next_defined, &next),
          "fmi3UpdateDiscreteStates");
}

/* A step from t to t + h; with early:I, through the early returns on the way. */
static void fmu_do_step(Fmu *f, double t, double h) {
    if (!f->fmi3) {
        check(f->do_step(f->c, t, h, 1), "fmi2DoStep");
        return;
    }
    double now = t, end = t + h;
    for (;;) {
        bool event = false, terminate = false, early = false;
        double last = 0.0;
        check(f->do_step3(f->c, now, end - now, true, &event, &terminate, &early, &last), "fmi3DoStep");
        bool legal = !terminate && (f->early ? (!early || (last > now && last < end)) && (!event || f->early)
                                             : !event && !early);
        if (!legal || (!early && last != end)) {
            fprintf(stderr, "fmu_host: fmi3DoStep at %g: event %d, terminate %d, early return %d, reached %g\n", now,
                    event, terminate, early, last);
            exit(1);
        }
        if (early) fprintf(stderr, "fmu_host: early return at %.17g\n", last);
        if (event) {
            check(f->enter_event_mode3(f->c), "fmi3EnterEventMode");
            fmu_update_discrete_states(f);
            check(f->enter_step_mode3(f->c), "fmi3EnterStepMode");
        }
        if (!early) return;
        now = last;
    }
}

/* In Initialization Mode: the Clock's interval must be the host's step. */
static void check_interval(Fmu *f, double h) {
    double interval;
    int qualifier;
    check(f->get_interval3(f->c, &f->clock, 1, &interval, &qualifier), "fmi3GetIntervalDecimal");
    if (interval != h) {
        fprintf(stderr, "fmu_host: the Clock's interval %.17g differs from the step %.17g\n", interval, h);
        exit(2);
    }
}

/* The input of a link or ramp op at time t. */
static double input(Fmu *fmus, const Op *op, double t) {
    return op->kind == 'l' ? fmu_get_real(&fmus[op->src_fmu], op->src_vr) : op->value + op->slope * t;
}

/* An activation of FMU i's Clock at t, from Step Mode: FMI 3.0, 2.3.5. */
static void activate(Fmu *fmus, int i, Op *ops, int n_ops, double t) {
    Fmu *f = &fmus[i];
    bool active = true;
    check(f->enter_event_mode3(f->c), "fmi3EnterEventMode");
    check(f->set_clock3(f->c, &f->clock, 1, &active), "fmi3SetClock");
    for (int j = 0; j < n_ops; j++) {
        if (ops[j].fmu == i && (ops[j].kind == 'l' || ops[j].kind == 'm')) fmu_set_real(f, ops[j].vr, input(fmus, &ops[j], t));
    }
    for (int j = 0; j < n_ops; j++) {
        if (ops[j].fmu == i && ops[j].kind == 'p') ops[j].read = fmu_get_real(f, ops[j].vr);
    }
    fmu_update_discrete_states(f);
    check(f->enter_step_mode3(f->c), "fmi3EnterStepMode");
}

static void fmu_free(Fmu *f) {
    check(f->terminate(f->c), f->fmi3 ? "fmi3Terminate" : "fmi2Terminate");
    f->free_instance(f->c);
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
    else if (sscanf(s, "clock:%d:%u", &op.fmu, &vr) == 2) op.kind = 'c';
    else if (sscanf(s, "intermediate:%d:%u", &op.fmu, &vr) == 2) op.kind = 'i';
    else if (sscanf(s, "early:%d", &op.fmu) == 1) op.kind = 'e';
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
        printf(" %.17g", fmus[ops[k].fmu].clocked ? ops[k].read : fmu_get_real(&fmus[ops[k].fmu], ops[k].vr));
    }
    printf("\n");
}

int main(int argc, char **argv) {
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    Fmu fmus[2] = {{0}, {0}};
    Op ops[MAX_OPS];
    int fmi3 = argc > 1 && strcmp(argv[1], "--fmi3") == 0;
    int n_fmus = 0, n_ops = 0, k = 3 + fmi3;
    if (argc < 6 + fmi3) {
        fprintf(stderr, "usage: fmu_host [--fmi3] STEPS H LIB GUID [LIB GUID] -- OP...\n");
        return 2;
    }
    long steps = atol(argv[1 + fmi3]);
    double h = atof(argv[2 + fmi3]);
    int first_lib = k;
    for (; k + 1 < argc && strcmp(argv[k], "--") != 0 && n_fmus < 2; k += 2) n_fmus++;
    for (k++; k < argc && n_ops < MAX_OPS; k++) ops[n_ops++] = parse(argv[k]);
    for (int j = 0; j < n_ops; j++) {
        if (ops[j].kind == 'c' && ops[j].fmu < n_fmus) fmus[ops[j].fmu].clocked = 1, fmus[ops[j].fmu].clock = ops[j].vr;
        if (ops[j].kind == 'e' && ops[j].fmu < n_fmus) {
            if (!fmi3) {
                fprintf(stderr, "fmu_host: early: needs --fmi3 (FMI 2.0 has no early return)\n");
                return 2;
            }
            fmus[ops[j].fmu].early = 1;
        }
        if (ops[j].kind == 'i' && ops[j].fmu < n_fmus) {
            if (!fmi3) {
                fprintf(stderr, "fmu_host: intermediate: needs --fmi3 (FMI 2.0 has input derivatives instead)\n");
                return 2;
            }
            Fmu *f = &fmus[ops[j].fmu];
            f->intermediate = 1, f->intermediate_vr = ops[j].vr;
            for (int m = 0; m < n_ops; m++) {
                if (ops[m].kind != 'm' || ops[m].fmu != ops[j].fmu || ops[m].vr != ops[j].vr) continue;
                f->line_x = ops[m].value, f->line_d = ops[m].slope;
            }
        }
    }
    for (int i = 0; i < n_fmus; i++) load(&fmus[i], fmi3, argv[first_lib + 2 * i], argv[first_lib + 2 * i + 1], &cb);

    double tolerance = 0.0;
    for (int j = 0; j < n_ops; j++) {
        if (ops[j].kind == 't') tolerance = ops[j].value;
    }
    for (int i = 0; i < n_fmus; i++) {
        for (int j = 0; j < n_ops; j++) {
            if (ops[j].kind == 'b' && ops[j].fmu == i) fmu_set_boolean(&fmus[i], ops[j].vr, ops[j].value != 0);
        }
        fmu_enter_init(&fmus[i], tolerance);
        for (int j = 0; j < n_ops; j++) {
            if (ops[j].kind == 'r' && ops[j].fmu == i) fmu_set_real(&fmus[i], ops[j].vr, ops[j].value);
        }
        if (fmus[i].clocked) check_interval(&fmus[i], h);
        fmu_exit_init(&fmus[i]);
        if (fmus[i].clocked || fmus[i].early) {
            fmu_update_discrete_states(&fmus[i]);
            check(fmus[i].enter_step_mode3(fmus[i].c), "fmi3EnterStepMode");
        }
    }
    for (long n = 0; n < steps; n++) {
        double t = n * h;
        for (int i = 0; i < n_fmus; i++) {
            for (int j = 0; j < n_ops && !fmus[i].clocked; j++) {
                if (ops[j].fmu == i && (ops[j].kind == 'l' || ops[j].kind == 'm')) fmu_set_real(&fmus[i], ops[j].vr, input(fmus, &ops[j], t));
            }
            fmu_do_step(&fmus[i], t, h);
            if (fmus[i].clocked) activate(fmus, i, ops, n_ops, (n + 1) * h);
        }
        if ((n + 1) % 100 == 0 || n + 1 == steps) print_outputs(fmus, ops, n_ops, (n + 1) * h);
    }
    for (int i = 0; i < n_fmus; i++) fmu_free(&fmus[i]);
    return 0;
}
