/* The FMI 2.0 Co-Simulation types and functions this FMU exports, declared from the
 * FMI 2.0.x standard (fmi2TypesPlatform.h, fmi2FunctionTypes.h, fmi2Functions.h:
 * standard 32-bit platform, no function prefix). Written for drymount. */
#ifndef DRYMOUNT_FMI2_API_H
#define DRYMOUNT_FMI2_API_H

#include <stddef.h>

#if defined(_WIN32)
#define FMI2_EXPORT __declspec(dllexport)
#elif defined(__GNUC__)
#define FMI2_EXPORT __attribute__((visibility("default")))
#else
#define FMI2_EXPORT
#endif

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

#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal,
               fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime,
               fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

/* Source-code FMU: an importer that defines FMI2_FUNCTION_PREFIX gets
 * every function prefixed (FMI2_FUNCTION_PREFIX=mount_: mount_fmi2DoStep, ...); the
 * binaries are built without it, with the standard names. */
#ifdef FMI2_FUNCTION_PREFIX
#define fmi2Paste(a, b) a##b
#define fmi2PasteB(a, b) fmi2Paste(a, b)
#define fmi2FullName(name) fmi2PasteB(FMI2_FUNCTION_PREFIX, name)
#define fmi2CancelStep fmi2FullName(fmi2CancelStep)
#define fmi2DeSerializeFMUstate fmi2FullName(fmi2DeSerializeFMUstate)
#define fmi2DoStep fmi2FullName(fmi2DoStep)
#define fmi2EnterInitializationMode fmi2FullName(fmi2EnterInitializationMode)
#define fmi2ExitInitializationMode fmi2FullName(fmi2ExitInitializationMode)
#define fmi2FreeFMUstate fmi2FullName(fmi2FreeFMUstate)
#define fmi2FreeInstance fmi2FullName(fmi2FreeInstance)
#define fmi2GetBoolean fmi2FullName(fmi2GetBoolean)
#define fmi2GetBooleanStatus fmi2FullName(fmi2GetBooleanStatus)
#define fmi2GetDirectionalDerivative fmi2FullName(fmi2GetDirectionalDerivative)
#define fmi2GetFMUstate fmi2FullName(fmi2GetFMUstate)
#define fmi2GetInteger fmi2FullName(fmi2GetInteger)
#define fmi2GetIntegerStatus fmi2FullName(fmi2GetIntegerStatus)
#define fmi2GetReal fmi2FullName(fmi2GetReal)
#define fmi2GetRealOutputDerivatives fmi2FullName(fmi2GetRealOutputDerivatives)
#define fmi2GetRealStatus fmi2FullName(fmi2GetRealStatus)
#define fmi2GetStatus fmi2FullName(fmi2GetStatus)
#define fmi2GetString fmi2FullName(fmi2GetString)
#define fmi2GetStringStatus fmi2FullName(fmi2GetStringStatus)
#define fmi2GetTypesPlatform fmi2FullName(fmi2GetTypesPlatform)
#define fmi2GetVersion fmi2FullName(fmi2GetVersion)
#define fmi2Instantiate fmi2FullName(fmi2Instantiate)
#define fmi2Reset fmi2FullName(fmi2Reset)
#define fmi2SerializeFMUstate fmi2FullName(fmi2SerializeFMUstate)
#define fmi2SerializedFMUstateSize fmi2FullName(fmi2SerializedFMUstateSize)
#define fmi2SetBoolean fmi2FullName(fmi2SetBoolean)
#define fmi2SetDebugLogging fmi2FullName(fmi2SetDebugLogging)
#define fmi2SetFMUstate fmi2FullName(fmi2SetFMUstate)
#define fmi2SetInteger fmi2FullName(fmi2SetInteger)
#define fmi2SetReal fmi2FullName(fmi2SetReal)
#define fmi2SetRealInputDerivatives fmi2FullName(fmi2SetRealInputDerivatives)
#define fmi2SetString fmi2FullName(fmi2SetString)
#define fmi2SetupExperiment fmi2FullName(fmi2SetupExperiment)
#define fmi2Terminate fmi2FullName(fmi2Terminate)
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define FMI2_API FMI2_EXPORT
FMI2_API const char *fmi2GetTypesPlatform(void);
FMI2_API const char *fmi2GetVersion(void);
FMI2_API fmi2Status fmi2SetDebugLogging(fmi2Component, fmi2Boolean, size_t,
                                        const fmi2String[]);
FMI2_API fmi2Component fmi2Instantiate(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions *, fmi2Boolean,
                                       fmi2Boolean);
FMI2_API void fmi2FreeInstance(fmi2Component);
FMI2_API fmi2Status fmi2SetupExperiment(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real,
                                        fmi2Boolean, fmi2Real);
FMI2_API fmi2Status fmi2EnterInitializationMode(fmi2Component);
FMI2_API fmi2Status fmi2ExitInitializationMode(fmi2Component);
FMI2_API fmi2Status fmi2Terminate(fmi2Component);
FMI2_API fmi2Status fmi2Reset(fmi2Component);
FMI2_API fmi2Status fmi2GetReal(fmi2Component, const fmi2ValueReference[], size_t,
                                fmi2Real[]);
FMI2_API fmi2Status fmi2GetInteger(fmi2Component, const fmi2ValueReference[], size_t,
                                   fmi2Integer[]);
FMI2_API fmi2Status fmi2GetBoolean(fmi2Component, const fmi2ValueReference[], size_t,
                                   fmi2Boolean[]);
FMI2_API fmi2Status fmi2GetString(fmi2Component, const fmi2ValueReference[], size_t,
                                  fmi2String[]);
FMI2_API fmi2Status fmi2SetReal(fmi2Component, const fmi2ValueReference[], size_t,
                                const fmi2Real[]);
FMI2_API fmi2Status fmi2SetInteger(fmi2Component, const fmi2ValueReference[], size_t,
                                   const fmi2Integer[]);
FMI2_API fmi2Status fmi2SetBoolean(fmi2Component, const fmi2ValueReference[], size_t,
                                   const fmi2Boolean[]);
FMI2_API fmi2Status fmi2SetString(fmi2Component, const fmi2ValueReference[], size_t,
                                  const fmi2String[]);
FMI2_API fmi2Status fmi2GetFMUstate(fmi2Component, fmi2FMUstate *);
FMI2_API fmi2Status fmi2SetFMUstate(fmi2Component, fmi2FMUstate);
FMI2_API fmi2Status fmi2FreeFMUstate(fmi2Component, fmi2FMUstate *);
FMI2_API fmi2Status fmi2SerializedFMUstateSize(fmi2Component, fmi2FMUstate, size_t *);
FMI2_API fmi2Status fmi2SerializeFMUstate(fmi2Component, fmi2FMUstate, fmi2Byte[],
                                          size_t);
FMI2_API fmi2Status fmi2DeSerializeFMUstate(fmi2Component, const fmi2Byte[], size_t,
                                            fmi2FMUstate *);
FMI2_API fmi2Status fmi2GetDirectionalDerivative(fmi2Component,
                                                 const fmi2ValueReference[], size_t,
                                                 const fmi2ValueReference[], size_t,
                                                 const fmi2Real[], fmi2Real[]);
FMI2_API fmi2Status fmi2SetRealInputDerivatives(fmi2Component,
                                                const fmi2ValueReference[], size_t,
                                                const fmi2Integer[], const fmi2Real[]);
FMI2_API fmi2Status fmi2GetRealOutputDerivatives(fmi2Component,
                                                 const fmi2ValueReference[], size_t,
                                                 const fmi2Integer[], fmi2Real[]);
FMI2_API fmi2Status fmi2DoStep(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
FMI2_API fmi2Status fmi2CancelStep(fmi2Component);
FMI2_API fmi2Status fmi2GetStatus(fmi2Component, const fmi2StatusKind, fmi2Status *);
FMI2_API fmi2Status fmi2GetRealStatus(fmi2Component, const fmi2StatusKind, fmi2Real *);
FMI2_API fmi2Status fmi2GetIntegerStatus(fmi2Component, const fmi2StatusKind,
                                         fmi2Integer *);
FMI2_API fmi2Status fmi2GetBooleanStatus(fmi2Component, const fmi2StatusKind,
                                         fmi2Boolean *);
FMI2_API fmi2Status fmi2GetStringStatus(fmi2Component, const fmi2StatusKind,
                                        fmi2String *);

#ifdef __cplusplus
}
#endif

#endif
