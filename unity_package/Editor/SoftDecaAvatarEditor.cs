using System.Collections.Generic;
using SoftDeca;
using SoftDeca.Unity;
using UnityEditor;
using UnityEngine;

namespace SoftDeca.Editor
{
    /// <summary>
    /// Material controls for SoftDecaAvatar: a slider per bundle parameter (its range and unit
    /// from the bundle), region controls (spheres on the face, moved in the Scene view), and the
    /// component's own fields.
    /// </summary>
    [CustomEditor(typeof(SoftDecaAvatar))]
    public sealed class SoftDecaAvatarEditor : UnityEditor.Editor
    {
        private ParameterInfo[] parameters;
        private string loadedFrom;
        private string loadError;

        public override void OnInspectorGUI()
        {
            var avatar = (SoftDecaAvatar)target;
            serializedObject.Update();
            DrawPropertiesExcluding(serializedObject, "parameters", "regions");
            LoadParameters(avatar);
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Material", EditorStyles.boldLabel);
            if (loadError != null) EditorGUILayout.HelpBox(loadError, MessageType.Warning);
            if (parameters != null)
                foreach (ParameterInfo p in parameters) ParameterSlider(avatar, p);
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Regions", EditorStyles.boldLabel);
            EditorGUILayout.PropertyField(serializedObject.FindProperty("regions"), true);
            if (serializedObject.ApplyModifiedProperties() || GUI.changed) avatar.MarkMaterialDirty();
        }

        private void LoadParameters(SoftDecaAvatar avatar)
        {
            if (avatar.Model != null)
            {
                parameters = avatar.Model.Parameters;
                return;
            }
            if (loadedFrom == avatar.bundlePath) return;
            loadedFrom = avatar.bundlePath;
            try
            {
                string path = System.IO.Path.IsPathRooted(avatar.bundlePath)
                                  ? avatar.bundlePath
                                  : System.IO.Path.Combine(Application.streamingAssetsPath, avatar.bundlePath);
                using (var model = Model.Load(path)) parameters = model.Parameters;
                loadError = null;
            }
            catch (System.Exception e)
            {
                parameters = null;
                loadError = "The bundle's parameters are not available: " + e.Message;
            }
        }

        private void ParameterSlider(SoftDecaAvatar avatar, ParameterInfo p)
        {
            int at = avatar.parameters.FindIndex(s => s.name == p.Name);
            float current = at >= 0 ? avatar.parameters[at].value : (float)p.DefaultValue;
            string label = string.IsNullOrEmpty(p.Unit) ? p.Name : p.Name + " (" + p.Unit + ")";
            EditorGUILayout.BeginHorizontal();
            float value = EditorGUILayout.Slider(new GUIContent(label, p.Description), current, (float)p.Min, (float)p.Max);
            bool reset = GUILayout.Button("Default", GUILayout.Width(60));
            EditorGUILayout.EndHorizontal();
            if (reset)
            {
                Undo.RecordObject(avatar, "Reset " + p.Name);
                if (at >= 0) avatar.parameters.RemoveAt(at);
                avatar.MarkMaterialDirty();
            }
            else if (value != current)
            {
                Undo.RecordObject(avatar, "Set " + p.Name);
                var setting = new ParameterSetting { name = p.Name, value = value };
                if (at >= 0) avatar.parameters[at] = setting;
                else avatar.parameters.Add(setting);
                avatar.MarkMaterialDirty();
            }
        }

        private void OnSceneGUI()
        {
            var avatar = (SoftDecaAvatar)target;
            Transform t = avatar.transform;
            for (int i = 0; i < avatar.regions.Count; ++i)
            {
                MaterialRegion r = avatar.regions[i];
                Vector3 world = t.TransformPoint(r.centre);
                Handles.color = new Color(1f, 0.5f, 0.1f, 0.8f);
                EditorGUI.BeginChangeCheck();
                Vector3 moved = Handles.PositionHandle(world, t.rotation);
                float radius = Handles.RadiusHandle(t.rotation, world, r.radius * t.lossyScale.x) / Mathf.Max(t.lossyScale.x, 1e-6f);
                Handles.Label(world, r.parameter + " = " + r.value);
                if (EditorGUI.EndChangeCheck())
                {
                    Undo.RecordObject(avatar, "Move region");
                    r.centre = t.InverseTransformPoint(moved);
                    r.radius = radius;
                    avatar.regions[i] = r;
                    avatar.MarkMaterialDirty();
                }
            }
        }
    }
}
