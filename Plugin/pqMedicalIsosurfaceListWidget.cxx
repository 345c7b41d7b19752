// SPDX-License-Identifier: BSD-3-Clause
#include "pqMedicalIsosurfaceListWidget.h"

#include "pqApplicationCore.h"
#include "pqMedicalHistogramWidget.h"
#include "pqUndoStack.h"
#include "pqView.h"
#include "vtkCommand.h"
#include "vtkDataSetAttributes.h"
#include "vtkEventQtSlotConnect.h"
#include "vtkHistoPyramidIsoRepresentation.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkSMMedicalIsosurfaceInitializationHelper.h"
#include "vtkSMPropertyGroup.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMViewProxy.h"
#include "vtkScalarsToColors.h"
#if MEDISO_WITH_PYTHON
#include "pqPythonManager.h"
#endif

#include <QCheckBox>
#include <QColorDialog>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QMenu>
#include <QPixmap>
#include <QPushButton>
#include <QStyledItemDelegate>
#include <QTableWidget>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace
{
enum Column
{
  ValueColumn = 0,
  ColorColumn = 1,
  OpacityColumn = 2
};

QString FormatNumber(double value)
{
  return QString::number(value, 'g', 8);
}

// Tissues in Hounsfield units, as a CT shows them; colours from the list's
// palette (skin and bone first), skin and soft tissue see-through so what
// lies inside shows.
struct TissuePreset
{
  const char* Name;
  double Value;
  double Color[3];
  double Opacity;
};
const TissuePreset TissuePresets[] = {
  { QT_TRANSLATE_NOOP("pqMedicalIsosurfaceListWidget", "Skin"), -500.0, { 0.93, 0.75, 0.62 },
    0.35 },
  { QT_TRANSLATE_NOOP("pqMedicalIsosurfaceListWidget", "Soft tissue"), 40.0, { 0.80, 0.30, 0.28 },
    0.5 },
  { QT_TRANSLATE_NOOP("pqMedicalIsosurfaceListWidget", "Contrast vessels"), 200.0,
    { 0.85, 0.15, 0.15 }, 1.0 },
  { QT_TRANSLATE_NOOP("pqMedicalIsosurfaceListWidget", "Bone"), 400.0, { 0.96, 0.94, 0.86 }, 1.0 },
};

// A swatch drawn as the colour cell's icon: unlike the cell's background, an
// icon stays visible in a selected row.
QPixmap Swatch(const QColor& color)
{
  QPixmap swatch(36, 12);
  swatch.fill(color);
  return swatch;
}

#if MEDISO_WITH_PYTHON
// The GUI's Python (null where ParaView runs without it).
pqPythonManager* PythonManager()
{
  pqApplicationCore* core = pqApplicationCore::instance();
  return core ? qobject_cast<pqPythonManager*>(core->manager("PYTHON_MANAGER")) : nullptr;
}
#endif

// The Opacity column: the row's own opacity, which the editor edits, and
// after it the opacity drawn where that differs (kept in Qt::UserRole: a
// QTableWidgetItem's display and edit texts are one).
class OpacityDelegate : public QStyledItemDelegate
{
public:
  using QStyledItemDelegate::QStyledItemDelegate;

protected:
  void initStyleOption(QStyleOptionViewItem* option, const QModelIndex& index) const override
  {
    QStyledItemDelegate::initStyleOption(option, index);
    const QVariant drawn = index.data(Qt::UserRole);
    if (drawn.isValid())
    {
      option->text = pqMedicalIsosurfaceListWidget::tr("%1 (drawn %2)")
                       .arg(option->text, FormatNumber(drawn.toDouble()));
    }
  }
};
}

//------------------------------------------------------------------------------
pqMedicalIsosurfaceListWidget::pqMedicalIsosurfaceListWidget(
  vtkSMProxy* smproxy, vtkSMPropertyGroup* smgroup, QWidget* parentObject)
  : Superclass(smproxy, smgroup, parentObject)
  , Table(new QTableWidget(0, 3, this))
  , RangeLabel(new QLabel(this))
  , AddButton(new QToolButton(this))
  , RemoveButton(new QPushButton(tr("Remove"), this))
  , ColorEachSurface(new QCheckBox(tr("Color Each Surface"), this))
  , Histogram(new pqMedicalHistogramWidget(this))
  , PreviewTimer(new QTimer(this))
  , RangeWarning(new QLabel(this))
  , MeshButton(new QPushButton(tr("Make Mesh"), this))
  , Connections(vtkEventQtSlotConnect::New())
{
  this->setObjectName("MedicalIsosurfaceList");
  this->Table->setObjectName("Isosurfaces");
  this->RangeLabel->setObjectName("DataRange");
  this->AddButton->setObjectName("Add");
  this->RemoveButton->setObjectName("Remove");
  this->ColorEachSurface->setObjectName("ColorEachSurface");
  this->RangeWarning->setObjectName("RangeWarning");
  this->MeshButton->setObjectName("MakeMesh");

  this->Table->setHorizontalHeaderLabels({ tr("Isovalue"), tr("Color"), tr("Opacity") });
  this->Table->horizontalHeaderItem(ValueColumn)
    ->setToolTip(tr("The value each surface is drawn at, in the array's units (Hounsfield units "
                    "for a CT). Double-click to type one, or drag its marker in the histogram."));
  this->Table->horizontalHeaderItem(ColorColumn)
    ->setToolTip(tr("The color each surface is drawn in: its own with Color Each Surface "
                    "checked, else the solid color (solid) or the color map at the isovalue "
                    "(map). Double-click to choose one."));
  this->Table->horizontalHeaderItem(OpacityColumn)
    ->setToolTip(tr("Each surface's opacity, 0 (invisible) to 1 (opaque). Double-click to "
                    "edit it."));
  this->Table->horizontalHeader()->setSectionResizeMode(ValueColumn, QHeaderView::Stretch);
  this->Table->horizontalHeader()->setSectionResizeMode(ColorColumn, QHeaderView::Fixed);
  this->Table->horizontalHeader()->setSectionResizeMode(OpacityColumn, QHeaderView::Stretch);
  this->Table->setColumnWidth(ColorColumn, 70);
  this->Table->verticalHeader()->setVisible(false);
  this->Table->setSelectionBehavior(QAbstractItemView::SelectRows);
  this->Table->setMinimumHeight(110);
  this->Table->setMaximumHeight(180);
  this->Table->setToolTip(tr("One row per isosurface. Double-click a value or an opacity to "
                             "edit it, a colour to choose it (with Color Each Surface checked)."));
  this->RangeLabel->setToolTip(
    tr("Range of the array the surfaces are drawn from: the coloring array, or the active "
       "point scalars with Solid Color."));
  // Add: tissue presets, or a value of one's own.
  this->AddButton->setText(tr("Add"));
  this->AddButton->setPopupMode(QToolButton::InstantPopup);
  this->AddButton->setToolTip(
    tr("Add a surface: a tissue preset in Hounsfield units (for a CT) with its color and "
       "opacity, or another value (the middle of the data range for the first row, else a "
       "tenth of the range above the last row). Double-click the new value to edit it."));
  auto* presets = new QMenu(this->AddButton);
  presets->setToolTipsVisible(true);
  // What each preset shows on a CT, in TissuePresets' order.
  const QString presetTips[] = {
    tr("The skin's outer surface, translucent. Stay above -600 HU: below, foam padding and "
       "blankets show."),
    tr("Muscle and brain, translucent, inside the skin."),
    tr("Vessels filled with contrast agent (on a contrast-enhanced CT; without contrast this "
       "value gives thin bone)."),
    tr("Bone, opaque. Values from 1000 HU keep only dense cortical bone."),
  };
  static_assert(sizeof(presetTips) / sizeof(presetTips[0]) ==
      sizeof(TissuePresets) / sizeof(TissuePresets[0]),
    "a tooltip per preset");
  presets->setObjectName("Presets");
  for (int i = 0; i < static_cast<int>(sizeof(TissuePresets) / sizeof(TissuePresets[0])); ++i)
  {
    const TissuePreset& preset = TissuePresets[i];
    QAction* action = presets->addAction(
      QIcon(Swatch(QColor::fromRgbF(preset.Color[0], preset.Color[1], preset.Color[2]))),
      tr("%1 (%2 HU)").arg(tr(preset.Name)).arg(preset.Value));
    action->setObjectName(QString("Preset%1").arg(i));
    action->setToolTip(presetTips[i]);
    QObject::connect(action, &QAction::triggered, this, [this, i]() { this->addPreset(i); });
  }
  presets->addSeparator();
  QAction* other = presets->addAction(tr("Other value"));
  other->setObjectName("OtherValue");
  other->setToolTip(tr("A row in the next palette color: the middle of the data range for the "
                       "first row, else a tenth of the range above the last row."));
  QObject::connect(other, &QAction::triggered, this, &pqMedicalIsosurfaceListWidget::addRow);
  this->AddButton->setMenu(presets);
  this->RemoveButton->setToolTip(
    tr("Remove the selected rows (the last row when none is selected)."));
  this->ColorEachSurface->setToolTip(
    tr("Draw each surface in its own color. Unchecked: Solid Color, or the color map at the "
       "isovalue when coloring by an array."));

  auto* buttons = new QHBoxLayout;
  buttons->setContentsMargins(0, 0, 0, 0);
  buttons->addWidget(this->AddButton);
  buttons->addWidget(this->RemoveButton);
  buttons->addStretch(1);
  buttons->addWidget(this->ColorEachSurface);

  // Opacities drawn, the out-of-range warning, the mesh of what is shown.
  this->Table->setItemDelegateForColumn(OpacityColumn, new OpacityDelegate(this->Table));
  this->RangeWarning->setWordWrap(true);
  this->RangeWarning->setStyleSheet("QLabel { color: #b3261e; }");
  this->RangeWarning->setVisible(false);
  this->MeshButton->setToolTip(
    tr("Make the surfaces shown a mesh to save (File > Save Data: STL, PLY, VTP): a Block LOD "
       "Contour of this display's input at these isovalues (Auto LOD: the finest level the "
       "memory estimator allows), each triangle labelled with its surface's color and name. "
       "Python: medical_isosurfaces.MakeMeshFromView()."));
#if MEDISO_WITH_PYTHON
  this->MeshButton->setVisible(PythonManager() != nullptr);
#else
  this->MeshButton->setVisible(false);
#endif
  buttons->addWidget(this->MeshButton);
  QObject::connect(
    this->MeshButton, &QPushButton::clicked, this, &pqMedicalIsosurfaceListWidget::makeMesh);
  QObject::connect(this, &pqPropertyWidget::viewChanged, this, [this](pqView* view) {
    QObject::disconnect(this->RenderConnection);
    if (view)
    {
      this->RenderConnection = QObject::connect(
        view, &pqView::endRender, this, &pqMedicalIsosurfaceListWidget::updateLooks);
    }
  });

  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(this->RangeLabel);
  layout->addWidget(this->Histogram);
  layout->addWidget(this->Table);
  layout->addWidget(this->RangeWarning);
  layout->addLayout(buttons);

  QObject::connect(
    this->RemoveButton, &QPushButton::clicked, this, &pqMedicalIsosurfaceListWidget::removeRows);
  QObject::connect(
    this->Table, &QTableWidget::cellChanged, this, &pqMedicalIsosurfaceListWidget::cellEdited);
  QObject::connect(this->Table, &QTableWidget::cellDoubleClicked, this,
    &pqMedicalIsosurfaceListWidget::cellDoubleClicked);
  // Checking the box (the user, not a property update) makes the colours
  // shown the colours drawn.
  QObject::connect(this->ColorEachSurface, &QCheckBox::toggled, this,
    &pqMedicalIsosurfaceListWidget::updateTable);
  QObject::connect(this->ColorEachSurface, &QCheckBox::clicked, this,
    &pqMedicalIsosurfaceListWidget::colorsChanged);
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerMoved, this,
    &pqMedicalIsosurfaceListWidget::previewMarker);
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerReleased, this,
    &pqMedicalIsosurfaceListWidget::commitMarker);
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerCancelled, this,
    &pqMedicalIsosurfaceListWidget::cancelMarker);
  // One preview render per pass of the event loop, however many moves came.
  this->PreviewTimer->setSingleShot(true);
  this->PreviewTimer->setInterval(0);
  QObject::connect(this->PreviewTimer, &QTimer::timeout, this,
    &pqMedicalIsosurfaceListWidget::renderPreview);

  vtkSMProperty* isovalues = smproxy->GetProperty("IsosurfaceValues");
  this->addPropertyLink(this, "values", SIGNAL(valuesChanged()), isovalues);
  this->addPropertyLink(this, "colors", SIGNAL(colorsChanged()), smgroup->GetProperty("Colors"));
  this->addPropertyLink(
    this, "opacities", SIGNAL(opacitiesChanged()), smgroup->GetProperty("Opacities"));
  this->addPropertyLink(this->ColorEachSurface, "ColorEachSurface");

  // The range follows the data and the colouring.
  vtkSMPropertyHelper input(smproxy, "Input", /*quiet=*/true);
  if (auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy()))
  {
    this->Connections->Connect(source, vtkCommand::UpdateDataEvent, this, SLOT(updateRange()));
  }
  if (vtkSMProperty* colorArray = smproxy->GetProperty("ColorArrayName"))
  {
    this->Connections->Connect(colorArray, vtkCommand::ModifiedEvent, this, SLOT(updateRange()));
    this->Connections->Connect(colorArray, vtkCommand::ModifiedEvent, this, SLOT(updateTable()));
  }
  for (const char* name : { "LookupTable", "DiffuseColor" })
  {
    if (vtkSMProperty* drawn = smproxy->GetProperty(name))
    {
      this->Connections->Connect(drawn, vtkCommand::ModifiedEvent, this, SLOT(updateTable()));
    }
  }
  this->updateRange();
  this->updateTable();

  // A display still at its HU start (skin and bone, nothing else set) gets
  // skin's and bone's look, once: skin over bone as soon as the type is chosen.
  const char* start = vtkSMMedicalIsosurfaceInitializationHelper::StartAnnotation();
  if (smproxy->HasAnnotation(start))
  {
    smproxy->RemoveAnnotation(start);
    vtkSMProperty* colorsProperty = smgroup->GetProperty("Colors");
    vtkSMProperty* opacitiesProperty = smgroup->GetProperty("Opacities");
    vtkSMProperty* colorEachProperty = smgroup->GetProperty("ColorEachSurface");
    double values[2];
    double colors[6];
    double opacities[2];
    vtkSMMedicalIsosurfaceInitializationHelper::GetSkinAndBone(values, colors, opacities);
    if (colorsProperty && opacitiesProperty && colorEachProperty &&
      vtkSMPropertyHelper(isovalues).GetArray<double>() ==
        std::vector<double>(values, values + 2) &&
      vtkSMPropertyHelper(colorsProperty).GetNumberOfElements() == 0 &&
      vtkSMPropertyHelper(opacitiesProperty).GetNumberOfElements() == 0 &&
      vtkSMPropertyHelper(colorEachProperty).GetAsInt() == 0)
    {
      vtkSMPropertyHelper(colorsProperty).Set(colors, 6);
      vtkSMPropertyHelper(opacitiesProperty).Set(opacities, 2);
      vtkSMPropertyHelper(colorEachProperty).Set(1);
      smproxy->UpdateVTKObjects();
    }
  }
}

//------------------------------------------------------------------------------
pqMedicalIsosurfaceListWidget::~pqMedicalIsosurfaceListWidget()
{
  this->Connections->Disconnect();
  this->Connections->Delete();
}

//------------------------------------------------------------------------------
QColor pqMedicalIsosurfaceListWidget::defaultColor(int row)
{
  static const QColor palette[] = { QColor::fromRgbF(0.93, 0.75, 0.62),
    QColor::fromRgbF(0.96, 0.94, 0.86), QColor::fromRgbF(0.80, 0.30, 0.28),
    QColor::fromRgbF(0.35, 0.55, 0.85), QColor::fromRgbF(0.45, 0.75, 0.40),
    QColor::fromRgbF(0.90, 0.75, 0.25), QColor::fromRgbF(0.65, 0.45, 0.80),
    QColor::fromRgbF(0.40, 0.80, 0.80) };
  return palette[row % (sizeof(palette) / sizeof(palette[0]))];
}

//------------------------------------------------------------------------------
QList<QVariant> pqMedicalIsosurfaceListWidget::values() const
{
  QList<QVariant> list;
  for (const Row& row : this->Rows)
  {
    list.push_back(row.Value);
  }
  return list;
}

//------------------------------------------------------------------------------
QList<QVariant> pqMedicalIsosurfaceListWidget::colors() const
{
  QList<QVariant> list;
  for (const Row& row : this->Rows)
  {
    list << row.Color.redF() << row.Color.greenF() << row.Color.blueF();
  }
  return list;
}

//------------------------------------------------------------------------------
QList<QVariant> pqMedicalIsosurfaceListWidget::opacities() const
{
  QList<QVariant> list;
  for (const Row& row : this->Rows)
  {
    list.push_back(row.Opacity);
  }
  return list;
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::setValues(const QList<QVariant>& values)
{
  const std::size_t old = this->Rows.size();
  this->Rows.resize(static_cast<std::size_t>(values.size()));
  for (std::size_t i = 0; i < this->Rows.size(); ++i)
  {
    this->Rows[i].Value = values[static_cast<int>(i)].toDouble();
    if (i >= old)
    {
      this->Rows[i].Color = defaultColor(static_cast<int>(i));
      this->Rows[i].Opacity = 1.0;
    }
  }
  this->updateTable();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::setColors(const QList<QVariant>& colors)
{
  for (std::size_t i = 0; i < this->Rows.size(); ++i)
  {
    const int at = 3 * static_cast<int>(i);
    this->Rows[i].Color = at + 2 < colors.size()
      ? QColor::fromRgbF(std::min(1.0, std::max(0.0, colors[at].toDouble())),
          std::min(1.0, std::max(0.0, colors[at + 1].toDouble())),
          std::min(1.0, std::max(0.0, colors[at + 2].toDouble())))
      : defaultColor(static_cast<int>(i));
  }
  this->updateTable();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::setOpacities(const QList<QVariant>& opacities)
{
  for (std::size_t i = 0; i < this->Rows.size(); ++i)
  {
    this->Rows[i].Opacity =
      static_cast<int>(i) < opacities.size() ? opacities[static_cast<int>(i)].toDouble() : 1.0;
  }
  this->updateTable();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::updateTable()
{
  this->Updating = true;
  const bool colorEach = this->ColorEachSurface->isChecked();
  std::vector<double> values;
  std::vector<QColor> colors;
  this->Table->setRowCount(static_cast<int>(this->Rows.size()));
  for (int i = 0; i < static_cast<int>(this->Rows.size()); ++i)
  {
    const Row& row = this->Rows[static_cast<std::size_t>(i)];
    auto* value = new QTableWidgetItem(FormatNumber(row.Value));
    value->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
    this->Table->setItem(i, ValueColumn, value);
    auto* color = new QTableWidgetItem();
    color->setFlags(Qt::ItemIsSelectable | Qt::ItemIsEnabled);
    const QColor drawn = this->drawnColor(row);
    colors.push_back(drawn);
    values.push_back(row.Value);
    // The swatch is an icon: unlike a background, it shows in a selected row.
    color->setData(Qt::DecorationRole, Swatch(drawn));
    if (colorEach)
    {
      color->setBackground(row.Color);
      color->setToolTip(tr("Double-click to choose this surface's color"));
    }
    else
    {
      // Drawn in the solid colour or the colour map's colour at the value.
      vtkSMPropertyHelper colorArray(this->proxy(), "ColorArrayName", /*quiet=*/true);
      const char* name = colorArray.GetInputArrayNameToProcess();
      color->setText((name && name[0]) ? tr("map") : tr("solid"));
      color->setTextAlignment(Qt::AlignCenter);
      color->setToolTip((name && name[0])
          ? tr("Drawn in the color map's color at the isovalue. Double-click (or check Color "
               "Each Surface) to give this surface its own color")
          : tr("Drawn in the display's solid color. Double-click (or check Color Each "
               "Surface) to give this surface its own color"));
      color->setForeground(this->palette().color(QPalette::Disabled, QPalette::Text));
    }
    this->Table->setItem(i, ColorColumn, color);
    auto* opacity = new QTableWidgetItem(FormatNumber(row.Opacity));
    opacity->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
    if (this->HasRange && !(row.Value >= this->Range[0] && row.Value <= this->Range[1]))
    {
      opacity->setData(Qt::UserRole, 0.0);
      opacity->setToolTip(tr("Outside the data range: not drawn."));
    }
    else if (static_cast<std::size_t>(i) < this->DrawnOpacities.size() &&
      std::abs(this->DrawnOpacities[static_cast<std::size_t>(i)] - row.Opacity) > 1e-6)
    {
      opacity->setData(Qt::UserRole, this->DrawnOpacities[static_cast<std::size_t>(i)]);
      opacity->setToolTip(tr("Drawn at %1: this surface's opacity times the opacity map at its "
                             "value (while the color map's opacity mapping is enabled) and the "
                             "display's Opacity. Double-click to edit this surface's own.")
                            .arg(FormatNumber(this->DrawnOpacities[static_cast<std::size_t>(i)])));
    }
    this->Table->setItem(i, OpacityColumn, opacity);
  }
  this->RemoveButton->setEnabled(!this->Rows.empty());
  this->Histogram->setMarkers(values, colors);
  this->Updating = false;
  this->updateWarning();
}

//------------------------------------------------------------------------------
QColor pqMedicalIsosurfaceListWidget::drawnColor(const Row& row) const
{
  if (this->ColorEachSurface->isChecked())
  {
    return row.Color;
  }
  vtkSMProxy* display = this->proxy();
  vtkSMPropertyHelper colorArray(display, "ColorArrayName", /*quiet=*/true);
  const char* name = colorArray.GetInputArrayNameToProcess();
  if (name && name[0])
  {
    // The map's colour at the isovalue, from the client's copy of the map
    // (transfer functions live on the client too: the colour legend uses it).
    vtkSMPropertyHelper map(display, "LookupTable", /*quiet=*/true);
    vtkSMProxy* lut = map.GetAsProxy();
    auto* colors = lut ? vtkScalarsToColors::SafeDownCast(lut->GetClientSideObject()) : nullptr;
    if (colors && std::isfinite(row.Value))
    {
      double rgb[3];
      colors->GetColor(row.Value, rgb);
      return QColor::fromRgbF(rgb[0], rgb[1], rgb[2]);
    }
    return this->palette().color(QPalette::Disabled, QPalette::Text);
  }
  double rgb[3] = { 1.0, 1.0, 1.0 };
  if (display->GetProperty("DiffuseColor"))
  {
    vtkSMPropertyHelper(display, "DiffuseColor").Get(rgb, 3);
  }
  return QColor::fromRgbF(std::min(1.0, std::max(0.0, rgb[0])),
    std::min(1.0, std::max(0.0, rgb[1])), std::min(1.0, std::max(0.0, rgb[2])));
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::setValuesOutsideUndo(const std::vector<double>& values)
{
  const pqScopedUndoExclude outside;
  vtkSMProxy* display = this->proxy();
  vtkSMPropertyHelper(display, "IsosurfaceValues")
    .Set(values.data(), static_cast<unsigned int>(values.size()));
  display->UpdateVTKObjects();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::previewMarker(int row, double value)
{
  if (row < 0 || row >= static_cast<int>(this->Rows.size()))
  {
    return;
  }
  if (this->BeforeDrag.empty())
  {
    this->BeforeDrag = vtkSMPropertyHelper(this->proxy(), "IsosurfaceValues").GetArray<double>();
  }
  this->Rows[static_cast<std::size_t>(row)].Value = value;
  std::vector<double> values;
  for (const Row& each : this->Rows)
  {
    values.push_back(each.Value);
  }
  this->setValuesOutsideUndo(values);
  this->PreviewTimer->start();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::renderPreview()
{
  pqView* view = this->view();
  if (vtkSMViewProxy* viewProxy = view ? view->getViewProxy() : nullptr)
  {
    viewProxy->InteractiveRender();
  }
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::commitMarker(int row, double value)
{
  this->PreviewTimer->stop();
  if (!this->BeforeDrag.empty())
  {
    // The undo step must start from the values before the drag, not from the
    // last preview.
    const std::vector<double> before = this->BeforeDrag;
    this->BeforeDrag.clear();
    this->setValuesOutsideUndo(before);
  }
  if (row < 0 || row >= static_cast<int>(this->Rows.size()))
  {
    return;
  }
  // As a typed value: the panel applies it in one undo set and renders.
  this->Rows[static_cast<std::size_t>(row)].Value = value;
  this->rowsEdited();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::cancelMarker(int, double)
{
  this->PreviewTimer->stop();
  if (this->BeforeDrag.empty())
  {
    return;
  }
  const std::vector<double> before = this->BeforeDrag;
  this->BeforeDrag.clear();
  this->setValuesOutsideUndo(before);
  if (pqView* view = this->view())
  {
    view->render();
  }
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::rowsEdited()
{
  this->updateTable();
  Q_EMIT this->valuesChanged();
  Q_EMIT this->colorsChanged();
  Q_EMIT this->opacitiesChanged();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::addRow()
{
  Row row;
  const double span = this->HasRange ? this->Range[1] - this->Range[0] : 0.0;
  if (this->Rows.empty())
  {
    row.Value = this->HasRange ? this->Range[0] + 0.5 * span : 0.0;
  }
  else
  {
    // A tenth of the range above the last value, kept inside the range.
    row.Value = this->Rows.back().Value + (span > 0.0 ? 0.1 * span : 1.0);
    if (this->HasRange && row.Value > this->Range[1])
    {
      row.Value = this->Range[0] + 0.5 * span;
    }
  }
  row.Color = defaultColor(static_cast<int>(this->Rows.size()));
  this->appendRow(row);
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::addPreset(int index)
{
  const TissuePreset& preset = TissuePresets[index];
  Row row;
  row.Value = preset.Value;
  row.Color = QColor::fromRgbF(preset.Color[0], preset.Color[1], preset.Color[2]);
  row.Opacity = preset.Opacity;
  // A tissue's colour is part of the preset: draw it.
  this->ColorEachSurface->setChecked(true);
  this->appendRow(row);
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::appendRow(const Row& row)
{
  this->Rows.push_back(row);
  this->rowsEdited();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::removeRows()
{
  std::vector<int> selected;
  for (const QModelIndex& index : this->Table->selectionModel()->selectedRows())
  {
    selected.push_back(index.row());
  }
  if (selected.empty() && !this->Rows.empty())
  {
    selected.push_back(static_cast<int>(this->Rows.size()) - 1);
  }
  std::sort(selected.rbegin(), selected.rend());
  for (int row : selected)
  {
    this->Rows.erase(this->Rows.begin() + row);
  }
  this->rowsEdited();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::cellEdited(int row, int column)
{
  if (this->Updating || row < 0 || row >= static_cast<int>(this->Rows.size()))
  {
    return;
  }
  Row& edited = this->Rows[static_cast<std::size_t>(row)];
  bool ok = false;
  const double number = this->Table->item(row, column)->text().toDouble(&ok);
  if (column == ValueColumn && ok)
  {
    edited.Value = number;
  }
  else if (column == OpacityColumn && ok && std::isfinite(number))
  {
    edited.Opacity = std::min(1.0, std::max(0.0, number));
  }
  // Text that is not a number puts the old value back.
  this->rowsEdited();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::cellDoubleClicked(int row, int column)
{
  if (column != ColorColumn || row < 0 || row >= static_cast<int>(this->Rows.size()))
  {
    return;
  }
  if (!this->ColorEachSurface->isChecked())
  {
    // Choosing a colour means wanting colours per surface.
    this->ColorEachSurface->setChecked(true);
  }
  Row& edited = this->Rows[static_cast<std::size_t>(row)];
  const QColor chosen =
    QColorDialog::getColor(edited.Color, this, tr("Surface %1 color").arg(row + 1));
  if (chosen.isValid())
  {
    edited.Color = chosen;
    this->rowsEdited();
  }
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::updateRange()
{
  this->HasRange = false;
  vtkSMPropertyHelper input(this->proxy(), "Input", /*quiet=*/true);
  auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy());
  vtkPVArrayInformation* array = nullptr;
  if (source)
  {
    vtkPVDataSetAttributesInformation* points =
      source->GetDataInformation(input.GetOutputPort())->GetPointDataInformation();
    vtkSMPropertyHelper colorArray(this->proxy(), "ColorArrayName", /*quiet=*/true);
    const char* name = colorArray.GetInputArrayNameToProcess();
    array = (name && name[0]) ? points->GetArrayInformation(name)
                              : points->GetAttributeInformation(vtkDataSetAttributes::SCALARS);
  }
  if (array && array->GetNumberOfComponents() == 1)
  {
    array->GetComponentRange(0, this->Range);
    this->HasRange = this->Range[0] <= this->Range[1];
  }
  if (this->HasRange)
  {
    vtkSMPropertyHelper colorArray(this->proxy(), "ColorArrayName", /*quiet=*/true);
    this->Histogram->gatherHistogram(
      source, input.GetOutputPort(), colorArray.GetInputArrayNameToProcess());
  }
  else
  {
    this->Histogram->clearHistogram();
  }
  if (this->HasRange)
  {
    this->RangeLabel->setText(tr("Data range: [%1, %2] (%3)")
                                .arg(FormatNumber(this->Range[0]))
                                .arg(FormatNumber(this->Range[1]))
                                .arg(array->GetName() ? array->GetName() : "scalars"));
  }
  else
  {
    this->RangeLabel->setText(tr("Data range: unknown (no one-component point array)"));
  }
  this->RangeName = this->HasRange && array->GetName() ? array->GetName() : "";
  // The rows outside the range and the warning follow the range.
  this->updateTable();
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::updateWarning()
{
  std::vector<double> values;
  for (const Row& row : this->Rows)
  {
    values.push_back(row.Value);
  }
  const std::string warning = this->HasRange
    ? vtkHistoPyramidIsoRepresentation::OutsideRangeMessage(values.data(),
        static_cast<int>(values.size()), this->Range, this->RangeName.c_str())
    : std::string();
  this->RangeWarning->setText(QString::fromStdString(warning));
  this->RangeWarning->setVisible(!warning.empty());
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::updateLooks()
{
  vtkSMProperty* looks = this->propertyGroup()->GetProperty("Looks");
  if (!looks)
  {
    return;
  }
  this->proxy()->UpdatePropertyInformation(looks);
  const std::vector<double> all = vtkSMPropertyHelper(looks).GetArray<double>();
  std::vector<double> drawn;
  for (std::size_t i = 3; i < all.size(); i += 4)
  {
    drawn.push_back(all[i]);
  }
  if (drawn != this->DrawnOpacities)
  {
    this->DrawnOpacities = drawn;
    this->updateTable();
  }
}

//------------------------------------------------------------------------------
void pqMedicalIsosurfaceListWidget::makeMesh()
{
#if MEDISO_WITH_PYTHON
  pqPythonManager* python = PythonManager();
  if (!python)
  {
    return;
  }
  // The one implementation, shared with pvpython: the plugin's Python module.
  const QString code = QString("import medical_isosurfaces\n"
                               "medical_isosurfaces._make_mesh_for_panel(%1, %2)\n")
                         .arg(this->proxy()->GetGlobalID())
                         .arg(this->view() ? this->view()->getProxy()->GetGlobalID() : 0);
  BEGIN_UNDO_SET(tr("Make Mesh"));
  python->executeCode(code.toUtf8());
  END_UNDO_SET();
#endif
}
