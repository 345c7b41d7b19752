// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   pqMedicalIsosurfaceListWidget
 * @brief   The "HistoPyramid Isosurface" representation's isovalue list.
 *
 * A property-group widget (panel_widget="medical_isosurface_list") that
 * shows one row per isosurface: its value, its colour and its opacity, with
 * the data range of the contoured array above the table. It edits three
 * properties of the display together, so that row i is always the value,
 * colour and opacity of the same surface:
 *
 * - the display's IsosurfaceValues (shared with the Volume representation
 *   type, so the list carries over when switching types);
 * - the group's "Colors" (r, g, b per row; used when "Color Each Surface",
 *   the group's "ColorEachSurface", is checked);
 * - the group's "Opacities" (one per row; multiplies the solid colour's or
 *   the colour map's opacity).
 *
 * The range is the one of the array the representation contours: the
 * colouring array when one is chosen, else the input's active point
 * scalars; it is refreshed when the data or the colouring changes.
 *
 * *Add* opens a menu of tissue presets in Hounsfield units (skin -500, soft
 * tissue 40, contrast-filled vessels 200, bone 400), each adding a row with
 * its colour and opacity (and turning Color Each Surface on, so the colour is
 * drawn), and "Other value", a row a tenth of the range above the last one.
 * A preset's value is a start: edit it in the row. The list also takes over
 * the display's start (vtkSMMedicalIsosurfaceInitializationHelper): its
 * colours and opacities stay with the rows whatever values are typed.
 *
 * Above the table, the array's histogram (pqMedicalHistogramWidget) marks
 * each isovalue in the colour its surface is drawn in. Dragging a marker
 * previews: each move sets IsosurfaceValues outside the undo stack and renders
 * the view interactively (vtkSMViewProxy::InteractiveRender, so a
 * representation's interactive levels apply), at most once per pass of the
 * event loop. On release the property goes back to its value before the drag,
 * still outside the undo stack, and the dragged value is then set through the
 * panel like a typed one: one undo step per drag, from the old value to the
 * new. Esc during the drag puts the old value back.
 *
 * The colour column always shows the colour a surface is drawn in, as an
 * icon (visible in a selected row too): its own colour with Color Each
 * Surface, else the solid colour or the colour map's colour at the value.
 *
 * The Opacity column edits each row's own opacity and shows, after each
 * render, the opacity the surface is drawn with where that differs (the
 * colour map's opacity map, when its opacity mapping is on, and the
 * display's Opacity multiply it: the representation's SurfaceLooks). Below
 * the list, a warning names isovalues outside the data range (the text the
 * representation gives in Output Messages). *Make Mesh* runs the plugin's
 * Python call medical_isosurfaces.MakeMeshFromView() on this display: the
 * surfaces as a Block LOD Contour + Isosurface Labels mesh to save (hidden
 * where ParaView has no Python).
 */
#ifndef pqMedicalIsosurfaceListWidget_h
#define pqMedicalIsosurfaceListWidget_h

#include "pqPropertyGroupWidget.h"

#include <QColor>
#include <QList>
#include <QVariant>
#include <string>
#include <vector>

class QCheckBox;
class QTimer;
class pqMedicalHistogramWidget;
class QLabel;
class QPushButton;
class QToolButton;
class QTableWidget;
class vtkEventQtSlotConnect;

class pqMedicalIsosurfaceListWidget : public pqPropertyGroupWidget
{
  Q_OBJECT
  Q_PROPERTY(QList<QVariant> values READ values WRITE setValues)
  Q_PROPERTY(QList<QVariant> colors READ colors WRITE setColors)
  Q_PROPERTY(QList<QVariant> opacities READ opacities WRITE setOpacities)
  typedef pqPropertyGroupWidget Superclass;

public:
  pqMedicalIsosurfaceListWidget(
    vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent = nullptr);
  ~pqMedicalIsosurfaceListWidget() override;

  ///@{
  /// The rows as the three properties hold them.
  QList<QVariant> values() const;
  QList<QVariant> colors() const;
  QList<QVariant> opacities() const;
  void setValues(const QList<QVariant>& values);
  void setColors(const QList<QVariant>& colors);
  void setOpacities(const QList<QVariant>& opacities);
  ///@}

Q_SIGNALS:
  void valuesChanged();
  void colorsChanged();
  void opacitiesChanged();

private Q_SLOTS:
  /// Adds a row a tenth of the range above the last (the middle of the range
  /// for the first).
  void addRow();
  /// Adds a tissue preset's row (index into the presets).
  void addPreset(int preset);
  void removeRows();
  void cellEdited(int row, int column);
  void cellDoubleClicked(int row, int column);
  void updateRange();
  /// Reads the opacities drawn (SurfaceLooks) after a render.
  void updateLooks();
  /// Says which isovalues lie outside the data range.
  void updateWarning();
  /// The mesh of the surfaces shown (medical_isosurfaces.MakeMeshFromView).
  void makeMesh();
  /// Rebuilds the table from Rows without signalling an edit.
  void updateTable();
  /// A histogram marker dragged to a value: preview it.
  void previewMarker(int row, double value);
  /// A drag released at a value: one undoable change from the old value.
  void commitMarker(int row, double value);
  /// A drag abandoned: the old values back, rendered.
  void cancelMarker(int row, double value);
  /// Renders the preview (interactive render of the panel's view).
  void renderPreview();

private:
  Q_DISABLE_COPY(pqMedicalIsosurfaceListWidget)

  struct Row
  {
    double Value = 0.0;
    QColor Color;
    double Opacity = 1.0;
  };

  /// Tells the links that every column changed (rows added, removed, edited).
  void rowsEdited();
  /// The colour a new row starts with (a fixed palette, skin and bone first).
  static QColor defaultColor(int row);

  void appendRow(const Row& row);
  /// The colour a row's surface is drawn in now (see the class comment).
  QColor drawnColor(const Row& row) const;
  /// Sets IsosurfaceValues itself (not through the panel), outside the undo stack.
  void setValuesOutsideUndo(const std::vector<double>& values);

  std::vector<Row> Rows;
  std::vector<double> DrawnOpacities;
  QMetaObject::Connection RenderConnection;
  double Range[2] = { 0.0, 0.0 };
  std::string RangeName;
  bool HasRange = false;
  bool Updating = false;
  QTableWidget* Table;
  QLabel* RangeLabel;
  QToolButton* AddButton;
  QPushButton* RemoveButton;
  QCheckBox* ColorEachSurface;
  pqMedicalHistogramWidget* Histogram;
  QTimer* PreviewTimer;
  /// IsosurfaceValues before the drag in progress (empty: no preview made).
  std::vector<double> BeforeDrag;
  QLabel* RangeWarning;
  QPushButton* MeshButton;
  vtkEventQtSlotConnect* Connections;
};

#endif
