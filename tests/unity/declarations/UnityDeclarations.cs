// DECLARATION-ONLY REFERENCE, NOT UNITY'S CODE: the few UnityEngine, UnityEditor, Unity.Collections
// and AR Foundation 6 / ARKit types the package's Unity layer uses, with their signatures and no
// behaviour (members throw). It exists so that tests/unity/compile-check can compile
// unity_package/Runtime and Editor here, where Unity cannot run; it is never shipped and proves
// only that the layer uses these APIs with these signatures.
#pragma warning disable 0067, 0649
using System;
using System.Collections.Generic;

namespace UnityEngine
{
    public class Object
    {
        public string name { get { throw new NotImplementedException(); } set { throw new NotImplementedException(); } }
        public static T Instantiate<T>(T original) where T : Object { throw new NotImplementedException(); }
        public static void Destroy(Object obj) { throw new NotImplementedException(); }
        public static T FindAnyObjectByType<T>() where T : Object { throw new NotImplementedException(); }
    }
    public class Component : Object
    {
        public Transform transform { get { throw new NotImplementedException(); } }
        public GameObject gameObject { get { throw new NotImplementedException(); } }
        public T GetComponent<T>() { throw new NotImplementedException(); }
        public T GetComponentInParent<T>() { throw new NotImplementedException(); }
    }
    public class Behaviour : Component { public bool enabled; }
    public class GameObject : Object { public T AddComponent<T>() where T : Component { throw new NotImplementedException(); } }
    public static class Debug
    {
        public static void Log(object message) { throw new NotImplementedException(); }
        public static void LogException(Exception exception, Object context) { throw new NotImplementedException(); }
    }
    public enum KeyCode { Space, LeftArrow, RightArrow }
    public static class Input { public static bool GetKeyDown(KeyCode key) { throw new NotImplementedException(); } }
    public class MonoBehaviour : Behaviour { }
    public class Transform : Component
    {
        public Quaternion rotation;
        public Quaternion localRotation;
        public Vector3 lossyScale;
        public Vector3 TransformPoint(Vector3 p) { throw new NotImplementedException(); }
        public Vector3 InverseTransformPoint(Vector3 p) { throw new NotImplementedException(); }
    }
    public struct Vector3
    {
        public float x, y, z;
        public Vector3(float x, float y, float z) { this.x = x; this.y = y; this.z = z; }
    }
    public struct Quaternion
    {
        public float x, y, z, w;
        public Quaternion(float x, float y, float z, float w) { this.x = x; this.y = y; this.z = z; this.w = w; }
    }
    // The members' values are Unity's (HumanBodyBones.Neck = 9, ...); the others are left out.
    public enum HumanBodyBones { Neck = 9, Head = 10, LeftEye = 21, RightEye = 22 }
    public class Animator : Behaviour
    {
        public bool isHuman { get { throw new NotImplementedException(); } }
        public Transform GetBoneTransform(HumanBodyBones humanBoneId) { throw new NotImplementedException(); }
    }
    public struct Color { public Color(float r, float g, float b, float a) { } }
    public class Mesh : Object
    {
        public Vector3[] vertices;
        public int[] triangles;
        public int vertexCount { get { throw new NotImplementedException(); } }
        public int blendShapeCount { get { throw new NotImplementedException(); } }
        public string GetBlendShapeName(int index) { throw new NotImplementedException(); }
        public int GetBlendShapeFrameCount(int index) { throw new NotImplementedException(); }
        public void GetBlendShapeFrameVertices(int shape, int frame, Vector3[] deltaVertices, Vector3[] deltaNormals,
                                               Vector3[] deltaTangents) { throw new NotImplementedException(); }
        public void MarkDynamic() { throw new NotImplementedException(); }
        public void SetVertices<T>(Unity.Collections.NativeArray<T> inVertices) where T : struct { throw new NotImplementedException(); }
        public void SetNormals<T>(Unity.Collections.NativeArray<T> inNormals) where T : struct { throw new NotImplementedException(); }
        public void RecalculateBounds() { throw new NotImplementedException(); }
    }
    public class MeshFilter : Component { public Mesh sharedMesh; }
    public class Renderer : Component { }
    public class SkinnedMeshRenderer : Renderer
    {
        public Mesh sharedMesh;
        public void SetBlendShapeWeight(int index, float value) { throw new NotImplementedException(); }
    }
    public class TextAsset : Object
    {
        public string text { get { throw new NotImplementedException(); } }
        public byte[] bytes { get { throw new NotImplementedException(); } }
    }
    public static class Application
    {
        public static string streamingAssetsPath { get { throw new NotImplementedException(); } }
        public static string temporaryCachePath { get { throw new NotImplementedException(); } }
    }
    public static class Time
    {
        public static float deltaTime { get { throw new NotImplementedException(); } }
        public static float time { get { throw new NotImplementedException(); } }
        public static int frameCount { get { throw new NotImplementedException(); } }
    }
    public static class SystemInfo { public static string deviceName { get { throw new NotImplementedException(); } } }
    public static class Mathf { public static float Max(float a, float b) { throw new NotImplementedException(); } }
    public class GUIContent { public GUIContent(string text, string tooltip) { } }
    public static class GUI { public static bool changed; }
    public class GUILayoutOption { }
    public static class GUILayout
    {
        public static bool Button(string text, params GUILayoutOption[] options) { throw new NotImplementedException(); }
        public static GUILayoutOption Width(float width) { throw new NotImplementedException(); }
    }
    public class GUIStyle { }
    [AttributeUsage(AttributeTargets.Class)] public sealed class AddComponentMenuAttribute : Attribute { public AddComponentMenuAttribute(string menu) { } }
    [AttributeUsage(AttributeTargets.Class)] public sealed class DisallowMultipleComponentAttribute : Attribute { }
    public class PropertyAttribute : Attribute { }
    [AttributeUsage(AttributeTargets.Field)] public sealed class TooltipAttribute : PropertyAttribute { public TooltipAttribute(string t) { } }
    [AttributeUsage(AttributeTargets.Field)] public sealed class RangeAttribute : PropertyAttribute { public RangeAttribute(float a, float b) { } }
    [AttributeUsage(AttributeTargets.Field)] public sealed class MinAttribute : PropertyAttribute { public MinAttribute(float m) { } }
}

namespace UnityEngine.Events
{
    public class UnityEvent<T0>
    {
        public void AddListener(Action<T0> call) { throw new NotImplementedException(); }
        public void RemoveListener(Action<T0> call) { throw new NotImplementedException(); }
    }
}

namespace Unity.Collections
{
    public enum Allocator { Invalid, None, Temp, TempJob, Persistent }
    public struct NativeArray<T> : IDisposable where T : struct
    {
        public NativeArray(int length, Allocator allocator) { throw new NotImplementedException(); }
        public int Length { get { throw new NotImplementedException(); } }
        public bool IsCreated { get { throw new NotImplementedException(); } }
        public T this[int index] { get { throw new NotImplementedException(); } set { throw new NotImplementedException(); } }
        public void Dispose() { throw new NotImplementedException(); }
    }
}

namespace Unity.Collections.LowLevel.Unsafe
{
    public static class NativeArrayUnsafeUtility
    {
        public static unsafe void* GetUnsafeReadOnlyPtr<T>(NativeArray<T> array) where T : struct { throw new NotImplementedException(); }
        public static unsafe void* GetUnsafePtr<T>(NativeArray<T> array) where T : struct { throw new NotImplementedException(); }
    }
}

namespace UnityEngine.XR.ARSubsystems
{
    public struct TrackableId { public static bool operator ==(TrackableId a, TrackableId b) { throw new NotImplementedException(); }
                                public static bool operator !=(TrackableId a, TrackableId b) { throw new NotImplementedException(); }
                                public override bool Equals(object o) { throw new NotImplementedException(); }
                                public override int GetHashCode() { throw new NotImplementedException(); } }
    public enum TrackingState { None, Limited, Tracking }
    public struct XRFaceBlendShape
    {
        public int blendShapeId { get { throw new NotImplementedException(); } }
        public float coefficient { get { throw new NotImplementedException(); } }
    }
    public struct XResultCode { public bool IsSuccess() { throw new NotImplementedException(); } }
    public struct Result<T> { public XResultCode status { get { throw new NotImplementedException(); } }
                              public T value { get { throw new NotImplementedException(); } } }
    public class XRFaceSubsystem
    {
        public Result<Unity.Collections.NativeArray<XRFaceBlendShape>> TryGetBlendShapes(TrackableId faceId,
                                                                                          Unity.Collections.Allocator allocator)
        { throw new NotImplementedException(); }
    }
}

namespace UnityEngine.XR.ARFoundation
{
    using UnityEngine.XR.ARSubsystems;
    public class ARTrackable : MonoBehaviour
    {
        public TrackableId trackableId { get { throw new NotImplementedException(); } }
        public TrackingState trackingState { get { throw new NotImplementedException(); } }
    }
    public class ARFace : ARTrackable
    {
        public Unity.Collections.NativeArray<Vector3> vertices { get { throw new NotImplementedException(); } }
        public Transform leftEye { get { throw new NotImplementedException(); } }
        public Transform rightEye { get { throw new NotImplementedException(); } }
    }
    public struct ARTrackablesChangedEventArgs<T>
    {
        public IReadOnlyList<T> added { get { throw new NotImplementedException(); } }
        public IReadOnlyList<T> updated { get { throw new NotImplementedException(); } }
        public IReadOnlyList<KeyValuePair<TrackableId, T>> removed { get { throw new NotImplementedException(); } }
    }
    public class ARFaceManager : MonoBehaviour
    {
        public Events.UnityEvent<ARTrackablesChangedEventArgs<ARFace>> trackablesChanged;
        public XRFaceSubsystem subsystem { get { throw new NotImplementedException(); } }
    }
}

namespace UnityEngine.XR.ARKit
{
    // Alphabetical, as in com.unity.xr.arkit (the package maps by name, not by this order).
    public enum ARKitBlendShapeLocation
    {
        BrowDownLeft, BrowDownRight, BrowInnerUp, BrowOuterUpLeft, BrowOuterUpRight, CheekPuff, CheekSquintLeft,
        CheekSquintRight, EyeBlinkLeft, EyeBlinkRight, EyeLookDownLeft, EyeLookDownRight, EyeLookInLeft, EyeLookInRight,
        EyeLookOutLeft, EyeLookOutRight, EyeLookUpLeft, EyeLookUpRight, EyeSquintLeft, EyeSquintRight, EyeWideLeft,
        EyeWideRight, JawForward, JawLeft, JawOpen, JawRight, MouthClose, MouthDimpleLeft, MouthDimpleRight,
        MouthFrownLeft, MouthFrownRight, MouthFunnel, MouthLeft, MouthLowerDownLeft, MouthLowerDownRight, MouthPressLeft,
        MouthPressRight, MouthPucker, MouthRight, MouthRollLower, MouthRollUpper, MouthShrugLower, MouthShrugUpper,
        MouthSmileLeft, MouthSmileRight, MouthStretchLeft, MouthStretchRight, MouthUpperUpLeft, MouthUpperUpRight,
        NoseSneerLeft, NoseSneerRight, TongueOut,
    }
}

namespace UnityEditor
{
    using UnityEngine;
    [AttributeUsage(AttributeTargets.Class)] public sealed class CustomEditorAttribute : Attribute { public CustomEditorAttribute(Type t) { } }
    public class SerializedProperty { }
    public class SerializedObject
    {
        public void Update() { throw new NotImplementedException(); }
        public bool ApplyModifiedProperties() { throw new NotImplementedException(); }
        public SerializedProperty FindProperty(string path) { throw new NotImplementedException(); }
    }
    public class Editor : ScriptableObjectStandIn
    {
        public Object target { get { throw new NotImplementedException(); } }
        public SerializedObject serializedObject { get { throw new NotImplementedException(); } }
        public virtual void OnInspectorGUI() { }
        public void Repaint() { throw new NotImplementedException(); }
        protected static void DrawPropertiesExcluding(SerializedObject obj, params string[] propertyToExclude) { throw new NotImplementedException(); }
    }
    public class ScriptableObjectStandIn : Object { }
    public enum MessageType { None, Info, Warning, Error }
    public static class EditorStyles { public static GUIStyle boldLabel { get { throw new NotImplementedException(); } } }
    public static class EditorGUILayout
    {
        public static void LabelField(string label, GUIStyle style) { throw new NotImplementedException(); }
        public static void LabelField(string label, string label2, params GUILayoutOption[] options) { throw new NotImplementedException(); }
        public static void Space() { throw new NotImplementedException(); }
        public static void HelpBox(string message, MessageType type) { throw new NotImplementedException(); }
        public static bool PropertyField(SerializedProperty property, bool includeChildren) { throw new NotImplementedException(); }
        public static float Slider(GUIContent label, float value, float left, float right) { throw new NotImplementedException(); }
        public static void BeginHorizontal() { throw new NotImplementedException(); }
        public static void EndHorizontal() { throw new NotImplementedException(); }
    }
    public static class EditorGUI
    {
        public static void BeginChangeCheck() { throw new NotImplementedException(); }
        public static bool EndChangeCheck() { throw new NotImplementedException(); }
        public static void BeginDisabledGroup(bool disabled) { throw new NotImplementedException(); }
        public static void EndDisabledGroup() { throw new NotImplementedException(); }
    }
    public sealed class EditorApplication
    {
        public delegate void CallbackFunction();
        public static CallbackFunction delayCall;
        public static bool isPlaying { get { throw new NotImplementedException(); } }
    }
    public static class EditorUtility
    {
        public static void DisplayProgressBar(string title, string info, float progress) { throw new NotImplementedException(); }
        public static void ClearProgressBar() { throw new NotImplementedException(); }
        public static void SetDirty(Object target) { throw new NotImplementedException(); }
    }
    public static class AssetDatabase
    {
        public static string GetAssetPath(Object assetObject) { throw new NotImplementedException(); }
        public static void ImportAsset(string path) { throw new NotImplementedException(); }
        public static T LoadAssetAtPath<T>(string assetPath) where T : Object { throw new NotImplementedException(); }
    }
    public static class Undo { public static void RecordObject(Object o, string name) { throw new NotImplementedException(); } }
    public static class Handles
    {
        public static Color color;
        public static Vector3 PositionHandle(Vector3 position, Quaternion rotation) { throw new NotImplementedException(); }
        public static float RadiusHandle(Quaternion rotation, Vector3 position, float radius) { throw new NotImplementedException(); }
        public static void Label(Vector3 position, string text) { throw new NotImplementedException(); }
    }
}
