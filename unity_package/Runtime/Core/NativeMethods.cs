// P/Invoke declarations of the C ABI (plugin/include/softdeca/softdeca.h). Only blittable
// types cross: pointers, fixed-width integers, float, double and the structs of NativeTypes.cs.
// No callbacks go from native code into managed code.
using System;
using System.Runtime.InteropServices;

namespace SoftDeca
{
    internal static unsafe class NativeMethods
    {
        /// <summary>SOFTDECA_ABI_VERSION of the header these declarations mirror.</summary>
        public const uint AbiVersion = 5;

#if (UNITY_IOS || UNITY_TVOS || UNITY_VISIONOS) && !UNITY_EDITOR
        // iOS links the static library into the app.
        public const string Library = "__Internal";
#else
        public const string Library = "softdeca";
#endif
        private const CallingConvention Cdecl = CallingConvention.Cdecl;

        // ---- library ----
        [DllImport(Library, CallingConvention = Cdecl)] public static extern uint softdeca_abi_version();
        [DllImport(Library, CallingConvention = Cdecl)] public static extern IntPtr softdeca_version();
        [DllImport(Library, CallingConvention = Cdecl)] public static extern IntPtr softdeca_last_error();
        [DllImport(Library, CallingConvention = Cdecl)] public static extern IntPtr softdeca_status_name(Status status);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern IntPtr softdeca_blendshape_get_name(uint index);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_blendshape_find_index(byte* name, out int index);

        // ---- model ----
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_load(byte* path, ref ModelOptions options, out IntPtr model);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_load_memory(byte* data, uint byteCount, ref ModelOptions options, out IntPtr model);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_model_destroy(IntPtr model);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_get_info(ModelHandle model, ref ModelInfo info);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_get_parameter_info(ModelHandle model, uint index, ref NativeParameterInfo info);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_find_parameter(ModelHandle model, byte* name, out uint index);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_get_landmark_vertices(ModelHandle model, int* vertices, uint capacity);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_get_skin_triangles(ModelHandle model, int* triangles, uint capacity);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_model_evaluate_landmarks(ModelHandle model, float* vertices, uint vertexCount,
                                                                      float* points, uint pointCapacity);

        // ---- avatar ----
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_create(ModelHandle model, ref AvatarDesc desc, out IntPtr avatar);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_avatar_destroy(IntPtr avatar);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_set_parameter(AvatarHandle avatar, uint index, double value);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_set_parameter_faces(AvatarHandle avatar, uint index, float* values, uint count);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_set_parameter_vertices(AvatarHandle avatar, uint index, float* values, uint count);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_avatar_reset_parameters(AvatarHandle avatar);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_get_parameter(AvatarHandle avatar, uint index, out double value, out int localised);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_get_identity(AvatarHandle avatar, float* identity, uint capacity);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_set_identity(AvatarHandle avatar, float* identity, uint count);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_avatar_prepare(AvatarHandle avatar);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_evaluate_weights(AvatarHandle avatar, float* weights, uint count, ref Output output);
        // avatars: raw handle pointers, each kept alive by the caller (SafeHandle.DangerousAddRef)
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_evaluate_weights_batch(IntPtr* avatars, uint avatarCount, float* weights, uint weightCount,
                                                                           Output* outputs, int* statuses);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_evaluate_surface(AvatarHandle avatar, float* weights, uint count, float* surface,
                                                                     uint vertexCount, ref Output output);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_calibrate_landmarks(AvatarHandle avatar, float* points, uint count);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_evaluate_landmarks(AvatarHandle avatar, float* points, uint count, ref Output output);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_evaluate_linear(AvatarHandle avatar, float* weights, uint count, ref Output output);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_set_dynamics(AvatarHandle avatar, int enabled);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_avatar_reset_dynamics(AvatarHandle avatar);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_get_stats(AvatarHandle avatar, ref AvatarStats stats);

        // ---- a user's own avatar: the fit and the fitted avatar ----
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_fit_options_init(ref FitOptions options);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_fit_create(ModelHandle model, ref NativeAvatarMesh mesh, ref FitOptions options,
                                                               out IntPtr fit);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_avatar_fit_destroy(IntPtr fit);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_avatar_fit_save(AvatarFitHandle fit, byte* path);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_fit_load(ModelHandle model, byte* path, out IntPtr fit);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_fit_get_report(AvatarFitHandle fit, byte* buffer, uint capacity, out uint length);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_avatar_fit_get_registered(AvatarFitHandle fit, float* points, uint pointCapacity,
                                                                       out uint vertexCount);

        // ---- receiver ----
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_receiver_config_init(ref ReceiverConfig config);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_create(ref ReceiverConfig config, out IntPtr receiver);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_receiver_destroy(IntPtr receiver);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_receiver_get_port(ReceiverHandle receiver, out uint port);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_get_next(ReceiverHandle receiver, double timeout, ref Frame frame, out int received);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_get_latest(ReceiverHandle receiver, ref Frame frame, out int received);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_get_stats(ReceiverHandle receiver, ref ReceiverStats stats);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_get_profile(ReceiverHandle receiver, out uint id, int* indices, uint capacity, out uint count);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_get_neutral(ReceiverHandle receiver, float* xyz, uint vertexCapacity, out uint vertexCount);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_request_neutral(ReceiverHandle receiver, out int sent);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_start_recording(ReceiverHandle receiver, byte* path, ref RecordingHeader header);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_receiver_stop_recording(ReceiverHandle receiver, out uint frames);

        // ---- recordings ----
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_recorder_create(byte* path, ref RecordingHeader header, out IntPtr recorder);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_recorder_write(RecorderHandle recorder, ref Frame frame);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_recorder_write_profile(RecorderHandle recorder, byte* name, int* indices, uint count, out uint id);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_recorder_write_neutral(RecorderHandle recorder, float* xyz, uint vertexCount);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_recorder_destroy(IntPtr recorder);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_player_load(byte* path, out IntPtr player);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern void softdeca_player_destroy(IntPtr player);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_get_info(PlayerHandle player, ref NativeRecordingInfo info);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_get_frame(PlayerHandle player, uint index, ref Frame frame);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_get_frame_at(PlayerHandle player, double time, ref Frame frame);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_player_seek(PlayerHandle player, double time);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_player_set_speed(PlayerHandle player, double speed);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_player_set_loop(PlayerHandle player, int loop);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_advance(PlayerHandle player, double dt, ref Frame frame, out int ended);
        [DllImport(Library, CallingConvention = Cdecl)] public static extern Status softdeca_player_get_position(PlayerHandle player, out double time);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_get_profile(PlayerHandle player, out uint id, int* indices, uint capacity, out uint count);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_player_get_neutral(PlayerHandle player, float* xyz, uint vertexCapacity, out uint vertexCount);
        [DllImport(Library, CallingConvention = Cdecl)]
        public static extern Status softdeca_convert_livelinkface_csv(byte* csvPath, byte* recordingPath, double timecodeRate,
                                                                      ref ConvertReport report);
    }
}
