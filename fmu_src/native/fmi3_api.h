/* The FMI 3.0 types and functions this FMU exports, declared from the FMI 3.0 standard
 * (fmi3PlatformTypes.h, fmi3FunctionTypes.h, fmi3Functions.h; no function prefix).
 * Written for drymount. */
#ifndef DRYMOUNT_FMI3_API_H
#define DRYMOUNT_FMI3_API_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Source-code FMU: an importer that defines FMI3_FUNCTION_PREFIX gets
 * every function prefixed (FMI3_FUNCTION_PREFIX=mount_: mount_fmi3DoStep, ...); the
 * binaries are built without it, with the standard names. */
#ifdef FMI3_FUNCTION_PREFIX
#define fmi3Paste(a, b) a##b
#define fmi3PasteB(a, b) fmi3Paste(a, b)
#define fmi3FullName(name) fmi3PasteB(FMI3_FUNCTION_PREFIX, name)
#define fmi3ActivateModelPartition fmi3FullName(fmi3ActivateModelPartition)
#define fmi3CompletedIntegratorStep fmi3FullName(fmi3CompletedIntegratorStep)
#define fmi3DeserializeFMUState fmi3FullName(fmi3DeserializeFMUState)
#define fmi3DoStep fmi3FullName(fmi3DoStep)
#define fmi3EnterConfigurationMode fmi3FullName(fmi3EnterConfigurationMode)
#define fmi3EnterContinuousTimeMode fmi3FullName(fmi3EnterContinuousTimeMode)
#define fmi3EnterEventMode fmi3FullName(fmi3EnterEventMode)
#define fmi3EnterInitializationMode fmi3FullName(fmi3EnterInitializationMode)
#define fmi3EnterStepMode fmi3FullName(fmi3EnterStepMode)
#define fmi3EvaluateDiscreteStates fmi3FullName(fmi3EvaluateDiscreteStates)
#define fmi3ExitConfigurationMode fmi3FullName(fmi3ExitConfigurationMode)
#define fmi3ExitInitializationMode fmi3FullName(fmi3ExitInitializationMode)
#define fmi3FreeFMUState fmi3FullName(fmi3FreeFMUState)
#define fmi3FreeInstance fmi3FullName(fmi3FreeInstance)
#define fmi3GetAdjointDerivative fmi3FullName(fmi3GetAdjointDerivative)
#define fmi3GetBinary fmi3FullName(fmi3GetBinary)
#define fmi3GetBoolean fmi3FullName(fmi3GetBoolean)
#define fmi3GetClock fmi3FullName(fmi3GetClock)
#define fmi3GetContinuousStateDerivatives \
    fmi3FullName(fmi3GetContinuousStateDerivatives)
#define fmi3GetContinuousStates fmi3FullName(fmi3GetContinuousStates)
#define fmi3GetDirectionalDerivative fmi3FullName(fmi3GetDirectionalDerivative)
#define fmi3GetEventIndicators fmi3FullName(fmi3GetEventIndicators)
#define fmi3GetFMUState fmi3FullName(fmi3GetFMUState)
#define fmi3GetFloat32 fmi3FullName(fmi3GetFloat32)
#define fmi3GetFloat64 fmi3FullName(fmi3GetFloat64)
#define fmi3GetInt16 fmi3FullName(fmi3GetInt16)
#define fmi3GetInt32 fmi3FullName(fmi3GetInt32)
#define fmi3GetInt64 fmi3FullName(fmi3GetInt64)
#define fmi3GetInt8 fmi3FullName(fmi3GetInt8)
#define fmi3GetIntervalDecimal fmi3FullName(fmi3GetIntervalDecimal)
#define fmi3GetIntervalFraction fmi3FullName(fmi3GetIntervalFraction)
#define fmi3GetNominalsOfContinuousStates \
    fmi3FullName(fmi3GetNominalsOfContinuousStates)
#define fmi3GetNumberOfContinuousStates fmi3FullName(fmi3GetNumberOfContinuousStates)
#define fmi3GetNumberOfEventIndicators fmi3FullName(fmi3GetNumberOfEventIndicators)
#define fmi3GetNumberOfVariableDependencies \
    fmi3FullName(fmi3GetNumberOfVariableDependencies)
#define fmi3GetOutputDerivatives fmi3FullName(fmi3GetOutputDerivatives)
#define fmi3GetShiftDecimal fmi3FullName(fmi3GetShiftDecimal)
#define fmi3GetShiftFraction fmi3FullName(fmi3GetShiftFraction)
#define fmi3GetString fmi3FullName(fmi3GetString)
#define fmi3GetUInt16 fmi3FullName(fmi3GetUInt16)
#define fmi3GetUInt32 fmi3FullName(fmi3GetUInt32)
#define fmi3GetUInt64 fmi3FullName(fmi3GetUInt64)
#define fmi3GetUInt8 fmi3FullName(fmi3GetUInt8)
#define fmi3GetVariableDependencies fmi3FullName(fmi3GetVariableDependencies)
#define fmi3GetVersion fmi3FullName(fmi3GetVersion)
#define fmi3InstantiateCoSimulation fmi3FullName(fmi3InstantiateCoSimulation)
#define fmi3InstantiateModelExchange fmi3FullName(fmi3InstantiateModelExchange)
#define fmi3InstantiateScheduledExecution \
    fmi3FullName(fmi3InstantiateScheduledExecution)
#define fmi3Reset fmi3FullName(fmi3Reset)
#define fmi3SerializeFMUState fmi3FullName(fmi3SerializeFMUState)
#define fmi3SerializedFMUStateSize fmi3FullName(fmi3SerializedFMUStateSize)
#define fmi3SetBinary fmi3FullName(fmi3SetBinary)
#define fmi3SetBoolean fmi3FullName(fmi3SetBoolean)
#define fmi3SetClock fmi3FullName(fmi3SetClock)
#define fmi3SetContinuousStates fmi3FullName(fmi3SetContinuousStates)
#define fmi3SetDebugLogging fmi3FullName(fmi3SetDebugLogging)
#define fmi3SetFMUState fmi3FullName(fmi3SetFMUState)
#define fmi3SetFloat32 fmi3FullName(fmi3SetFloat32)
#define fmi3SetFloat64 fmi3FullName(fmi3SetFloat64)
#define fmi3SetInt16 fmi3FullName(fmi3SetInt16)
#define fmi3SetInt32 fmi3FullName(fmi3SetInt32)
#define fmi3SetInt64 fmi3FullName(fmi3SetInt64)
#define fmi3SetInt8 fmi3FullName(fmi3SetInt8)
#define fmi3SetIntervalDecimal fmi3FullName(fmi3SetIntervalDecimal)
#define fmi3SetIntervalFraction fmi3FullName(fmi3SetIntervalFraction)
#define fmi3SetShiftDecimal fmi3FullName(fmi3SetShiftDecimal)
#define fmi3SetShiftFraction fmi3FullName(fmi3SetShiftFraction)
#define fmi3SetString fmi3FullName(fmi3SetString)
#define fmi3SetTime fmi3FullName(fmi3SetTime)
#define fmi3SetUInt16 fmi3FullName(fmi3SetUInt16)
#define fmi3SetUInt32 fmi3FullName(fmi3SetUInt32)
#define fmi3SetUInt64 fmi3FullName(fmi3SetUInt64)
#define fmi3SetUInt8 fmi3FullName(fmi3SetUInt8)
#define fmi3Terminate fmi3FullName(fmi3Terminate)
#define fmi3UpdateDiscreteStates fmi3FullName(fmi3UpdateDiscreteStates)
#endif

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#define FMI3_API __declspec(dllexport)
#elif defined(__GNUC__)
#define FMI3_API __attribute__((visibility("default")))
#else
#define FMI3_API
#endif

typedef void *fmi3Instance;
typedef void *fmi3InstanceEnvironment;
typedef void *fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char *fmi3String;
typedef uint8_t fmi3Byte;
typedef const fmi3Byte *fmi3Binary;
typedef bool fmi3Clock;

typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;
typedef enum { fmi3Independent, fmi3Constant, fmi3Fixed, fmi3Tunable, fmi3Discrete,
               fmi3Dependent } fmi3DependencyKind;
typedef enum { fmi3IntervalNotYetKnown, fmi3IntervalUnchanged,
               fmi3IntervalChanged } fmi3IntervalQualifier;

typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String,
                                       fmi3String);
typedef void (*fmi3ClockUpdateCallback)(fmi3InstanceEnvironment);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64,
                                               fmi3Boolean, fmi3Boolean, fmi3Boolean,
                                               fmi3Boolean, fmi3Boolean *,
                                               fmi3Float64 *);
typedef void (*fmi3LockPreemptionCallback)(void);
typedef void (*fmi3UnlockPreemptionCallback)(void);

#define VR_IN const fmi3ValueReference vr[], size_t nvr

FMI3_API const char *fmi3GetVersion(void);
FMI3_API fmi3Status fmi3SetDebugLogging(fmi3Instance, fmi3Boolean, size_t,
                                        const fmi3String[]);
FMI3_API fmi3Instance fmi3InstantiateModelExchange(fmi3String, fmi3String, fmi3String,
                                                   fmi3Boolean, fmi3Boolean,
                                                   fmi3InstanceEnvironment,
                                                   fmi3LogMessageCallback);
FMI3_API fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean, fmi3Boolean,
    fmi3Boolean, const fmi3ValueReference[], size_t, fmi3InstanceEnvironment,
    fmi3LogMessageCallback, fmi3IntermediateUpdateCallback);
FMI3_API fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
    fmi3InstanceEnvironment, fmi3LogMessageCallback, fmi3ClockUpdateCallback,
    fmi3LockPreemptionCallback, fmi3UnlockPreemptionCallback);
FMI3_API void fmi3FreeInstance(fmi3Instance);
FMI3_API fmi3Status fmi3EnterInitializationMode(fmi3Instance, fmi3Boolean, fmi3Float64,
                                                fmi3Float64, fmi3Boolean, fmi3Float64);
FMI3_API fmi3Status fmi3ExitInitializationMode(fmi3Instance);
FMI3_API fmi3Status fmi3EnterEventMode(fmi3Instance);
FMI3_API fmi3Status fmi3Terminate(fmi3Instance);
FMI3_API fmi3Status fmi3Reset(fmi3Instance);

#define FMI3_GETSET(T)                                                              \
    FMI3_API fmi3Status fmi3Get##T(fmi3Instance, VR_IN, fmi3##T[], size_t);         \
    FMI3_API fmi3Status fmi3Set##T(fmi3Instance, VR_IN, const fmi3##T[], size_t);
FMI3_GETSET(Float32)
FMI3_GETSET(Float64)
FMI3_GETSET(Int8)
FMI3_GETSET(UInt8)
FMI3_GETSET(Int16)
FMI3_GETSET(UInt16)
FMI3_GETSET(Int32)
FMI3_GETSET(UInt32)
FMI3_GETSET(Int64)
FMI3_GETSET(UInt64)
FMI3_GETSET(Boolean)
FMI3_GETSET(String)
FMI3_API fmi3Status fmi3GetBinary(fmi3Instance, VR_IN, size_t[], fmi3Binary[], size_t);
FMI3_API fmi3Status fmi3SetBinary(fmi3Instance, VR_IN, const size_t[],
                                  const fmi3Binary[], size_t);
FMI3_API fmi3Status fmi3GetClock(fmi3Instance, VR_IN, fmi3Clock[]);
FMI3_API fmi3Status fmi3SetClock(fmi3Instance, VR_IN, const fmi3Clock[]);

FMI3_API fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance,
                                                        fmi3ValueReference, size_t *);
FMI3_API fmi3Status fmi3GetVariableDependencies(fmi3Instance, fmi3ValueReference,
                                                size_t[], fmi3ValueReference[],
                                                size_t[], fmi3DependencyKind[],
                                                size_t);
FMI3_API fmi3Status fmi3GetFMUState(fmi3Instance, fmi3FMUState *);
FMI3_API fmi3Status fmi3SetFMUState(fmi3Instance, fmi3FMUState);
FMI3_API fmi3Status fmi3FreeFMUState(fmi3Instance, fmi3FMUState *);
FMI3_API fmi3Status fmi3SerializedFMUStateSize(fmi3Instance, fmi3FMUState, size_t *);
FMI3_API fmi3Status fmi3SerializeFMUState(fmi3Instance, fmi3FMUState, fmi3Byte[],
                                          size_t);
FMI3_API fmi3Status fmi3DeserializeFMUState(fmi3Instance, const fmi3Byte[], size_t,
                                            fmi3FMUState *);
FMI3_API fmi3Status fmi3GetDirectionalDerivative(fmi3Instance,
                                                 const fmi3ValueReference[], size_t,
                                                 const fmi3ValueReference[], size_t,
                                                 const fmi3Float64[], size_t,
                                                 fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3GetAdjointDerivative(fmi3Instance, const fmi3ValueReference[],
                                             size_t, const fmi3ValueReference[],
                                             size_t, const fmi3Float64[], size_t,
                                             fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3EnterConfigurationMode(fmi3Instance);
FMI3_API fmi3Status fmi3ExitConfigurationMode(fmi3Instance);
FMI3_API fmi3Status fmi3GetIntervalDecimal(fmi3Instance, VR_IN, fmi3Float64[],
                                           fmi3IntervalQualifier[]);
FMI3_API fmi3Status fmi3GetIntervalFraction(fmi3Instance, VR_IN, fmi3UInt64[],
                                            fmi3UInt64[], fmi3IntervalQualifier[]);
FMI3_API fmi3Status fmi3GetShiftDecimal(fmi3Instance, VR_IN, fmi3Float64[]);
FMI3_API fmi3Status fmi3GetShiftFraction(fmi3Instance, VR_IN, fmi3UInt64[],
                                         fmi3UInt64[]);
FMI3_API fmi3Status fmi3SetIntervalDecimal(fmi3Instance, VR_IN, const fmi3Float64[]);
FMI3_API fmi3Status fmi3SetIntervalFraction(fmi3Instance, VR_IN, const fmi3UInt64[],
                                            const fmi3UInt64[]);
FMI3_API fmi3Status fmi3SetShiftDecimal(fmi3Instance, VR_IN, const fmi3Float64[]);
FMI3_API fmi3Status fmi3SetShiftFraction(fmi3Instance, VR_IN, const fmi3UInt64[],
                                         const fmi3UInt64[]);
FMI3_API fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance);
FMI3_API fmi3Status fmi3UpdateDiscreteStates(fmi3Instance, fmi3Boolean *,
                                             fmi3Boolean *, fmi3Boolean *,
                                             fmi3Boolean *, fmi3Boolean *,
                                             fmi3Float64 *);
FMI3_API fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance);
FMI3_API fmi3Status fmi3CompletedIntegratorStep(fmi3Instance, fmi3Boolean,
                                                fmi3Boolean *, fmi3Boolean *);
FMI3_API fmi3Status fmi3SetTime(fmi3Instance, fmi3Float64);
FMI3_API fmi3Status fmi3SetContinuousStates(fmi3Instance, const fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance, fmi3Float64[],
                                                      size_t);
FMI3_API fmi3Status fmi3GetEventIndicators(fmi3Instance, fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3GetContinuousStates(fmi3Instance, fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance, fmi3Float64[],
                                                      size_t);
FMI3_API fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance, size_t *);
FMI3_API fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance, size_t *);
FMI3_API fmi3Status fmi3EnterStepMode(fmi3Instance);
FMI3_API fmi3Status fmi3GetOutputDerivatives(fmi3Instance, VR_IN, const fmi3Int32[],
                                             fmi3Float64[], size_t);
FMI3_API fmi3Status fmi3DoStep(fmi3Instance, fmi3Float64, fmi3Float64, fmi3Boolean,
                               fmi3Boolean *, fmi3Boolean *, fmi3Boolean *,
                               fmi3Float64 *);
FMI3_API fmi3Status fmi3ActivateModelPartition(fmi3Instance, fmi3ValueReference,
                                               fmi3Float64);

#ifdef __cplusplus
}
#endif

#endif
