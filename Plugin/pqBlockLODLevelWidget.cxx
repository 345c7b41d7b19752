// SPDX-License-Identifier: BSD-3-Clause
#include "pqBlockLODLevelWidget.h"

#include "pqMedicalHistogramWidget.h"
#include "pqUndoStack.h"
#include "pqView.h"
#include "vtkCommand.h"
#include "vtkEventQtSlotConnect.h"
#include "vtkSMPropertyGroup.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMPropertyIterator.h"
#include "vtkSMProxy.h"
#include "vtkSMRepresentationProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMUncheckedPropertyHelper.h"
#include "vtkSMViewProxy.h"
#include "vtkSmartPointer.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFont>
#include <QGridLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLocale>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QTableWidget>
#include <QTimer>

#include <vector>

namespace
{
constexpr int NumberOfLevels = 4;

enum Column
{
  LevelColumn = 0,
  TrianglesColumn = 1,
  MegabytesColumn = 2,
  SecondsColumn = 3,
  UsedColumn = 4
};
}

//------------------------------------------------------------------------------
pqBlockLODLevelWidget::pqBlockLODLevelWidget(
  vtkSMProxy* smproxy, vtkSMPropertyGroup* smgroup, QWidget* parentObject)
  : Superclass(smproxy, smgroup, parentObject)
  , AutoLOD(new QCheckBox(tr("Auto LOD"), this))
  , Level(new QSpinBox(this))
  , LevelNote(new QLabel(this))
  , MemoryBudget(new QDoubleSpinBox(this))
  , Table(new QTableWidget(NumberOfLevels, 5, this))
  , Caption(new QLabel(this))
  , Histogram(new pqMedicalHistogramWidget(this))
  , PreviewTimer(new QTimer(this))
  , Connections(vtkEventQtSlotConnect::New())
{
  this->setObjectName("BlockLODLevels");
  this->AutoLOD->setObjectName("AutoLOD");
  this->Level->setObjectName("LOD");
  this->LevelNote->setObjectName("LevelNote");
  this->MemoryBudget->setObjectName("MemoryBudget");
  this->Table->setObjectName("Estimates");
  this->Caption->setObjectName("EstimatesCaption");

  this->Level->setRange(0, NumberOfLevels - 1);
  this->Level->setMinimumWidth(this->Level->fontMetrics().horizontalAdvance(QStringLiteral("0000")) + 30);
  this->Level->setToolTip(tr("Level of detail when Auto LOD is off: 0, 1, 2, 3 sample the volume "
                             "with cube edges of 8, 4, 2, 1 voxels (3 is full resolution)."));
  this->AutoLOD->setToolTip(tr("Use the highest level whose estimated output fits the memory "
                               "budget; the level used is marked in the table."));
  this->MemoryBudget->setRange(0.0, 1.0e9);
  this->MemoryBudget->setDecimals(1);
  this->MemoryBudget->setSuffix(tr(" MB"));
  this->MemoryBudget->setToolTip(tr("Memory the output surface may take with Auto LOD, in MB "
                                    "(10^6 bytes), all isovalues together."));

  // Which numbers are estimates: the status column says it row by row (the
  // level used and cached levels are exact counts), the seconds always are.
  this->Table->setHorizontalHeaderLabels(
    { tr("Level"), tr("Triangles"), tr("MB"), tr("Est. Seconds"), tr("Status") });
  const QString countsTip = tr("Estimated before extraction for the first isovalue, except on "
                               "rows marked exact (the level used, and cached levels).");
  this->Table->horizontalHeaderItem(TrianglesColumn)->setToolTip(countsTip);
  this->Table->horizontalHeaderItem(MegabytesColumn)->setToolTip(countsTip);
  this->Table->horizontalHeaderItem(SecondsColumn)
    ->setToolTip(tr("Estimated extraction time, from a cost model fitted to this filter's runs: "
                    "it changes between Applies as the model learns. Cached: no extraction."));
  this->Table->horizontalHeaderItem(UsedColumn)
    ->setToolTip(tr("used: the level the last Apply extracted (exact counts); cached: extracted "
                    "before (exact counts); estimated: not extracted."));
  this->Table->verticalHeader()->setVisible(false);
  this->Table->setEditTriggers(QAbstractItemView::NoEditTriggers);
  this->Table->setSelectionMode(QAbstractItemView::NoSelection);
  this->Table->setFocusPolicy(Qt::NoFocus);
  QHeaderView* header = this->Table->horizontalHeader();
  header->setSectionResizeMode(QHeaderView::Stretch);
  header->setSectionResizeMode(LevelColumn, QHeaderView::ResizeToContents);
  header->setSectionResizeMode(UsedColumn, QHeaderView::ResizeToContents);
  int height = header->sizeHint().height() + 2 * this->Table->frameWidth();
  for (int level = 0; level < NumberOfLevels; ++level)
  {
    height += this->Table->verticalHeader()->sectionSize(level);
  }
  this->Table->setFixedHeight(height);
  this->Caption->setWordWrap(true);

  auto* layout = new QGridLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  auto* histogramCaption =
    new QLabel(tr("Histogram (log scale): drag a marker to change that isovalue."), this);
  histogramCaption->setObjectName("HistogramCaption");
  layout->addWidget(histogramCaption, 0, 0, 1, 3);
  layout->addWidget(this->Histogram, 1, 0, 1, 3);
  layout->addWidget(this->AutoLOD, 2, 0, 1, 3);
  layout->addWidget(new QLabel(tr("LOD"), this), 3, 0);
  layout->addWidget(this->Level, 3, 1);
  layout->addWidget(this->LevelNote, 3, 2);
  layout->addWidget(new QLabel(tr("Memory Budget"), this), 4, 0);
  layout->addWidget(this->MemoryBudget, 4, 1, 1, 2);
  layout->addWidget(this->Table, 5, 0, 1, 3);
  layout->addWidget(this->Caption, 6, 0, 1, 3);
  layout->setColumnStretch(2, 1);

  this->addPropertyLink(this->AutoLOD, "AutoLOD");
  this->addPropertyLink(this->Level, "LOD");
  this->addPropertyLink(this->MemoryBudget, "MemoryBudget");
  QObject::connect(
    this->AutoLOD, &QCheckBox::toggled, this, &pqBlockLODLevelWidget::updateEnabledState);

  // The estimates are information properties: pulled from the filter after
  // each of its updates (whoever ran it: Apply, a script, an animation).
  for (const char* function :
    { "EstimatedTriangles", "EstimatedMB", "EstimatedSeconds", "ChosenLevel" })
  {
    if (vtkSMProperty* info = smgroup->GetProperty(function))
    {
      this->Connections->Connect(info, vtkCommand::ModifiedEvent, this, SLOT(updateEstimates()));
    }
  }
  this->Connections->Connect(
    smproxy, vtkCommand::UpdateDataEvent, this, SLOT(pullEstimates()));
  this->pullEstimates();

  // The histogram: the input's contoured array, the isovalues marked.
  if (vtkSMProperty* contourValues = smproxy->GetProperty("ContourValues"))
  {
    this->addPropertyLink(this, "contourValues", SIGNAL(contourValuesChanged()), contourValues);
  }
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerReleased, this,
    &pqBlockLODLevelWidget::setDraggedValue);
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerMoved, this,
    &pqBlockLODLevelWidget::previewDraggedValue);
  QObject::connect(this->Histogram, &pqMedicalHistogramWidget::markerCancelled, this,
    &pqBlockLODLevelWidget::endPreview);
  // One preview per pass of the event loop, however many moves came.
  this->PreviewTimer->setSingleShot(true);
  this->PreviewTimer->setInterval(0);
  QObject::connect(
    this->PreviewTimer, &QTimer::timeout, this, &pqBlockLODLevelWidget::renderPreview);
  vtkSMPropertyHelper input(smproxy, "Input", /*quiet=*/true);
  if (auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy()))
  {
    this->Connections->Connect(source, vtkCommand::UpdateDataEvent, this, SLOT(updateHistogram()));
  }
  if (vtkSMProperty* array = smproxy->GetProperty("SelectInputScalars"))
  {
    this->Connections->Connect(array, vtkCommand::ModifiedEvent, this, SLOT(updateHistogram()));
    this->Connections->Connect(
      array, vtkCommand::UncheckedPropertyModifiedEvent, this, SLOT(updateHistogram()));
  }
  this->updateHistogram();
}

//------------------------------------------------------------------------------
QList<QVariant> pqBlockLODLevelWidget::contourValues() const
{
  return this->ContourValues;
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::setContourValues(const QList<QVariant>& values)
{
  this->ContourValues = values;
  std::vector<double> marked;
  for (const QVariant& value : values)
  {
    marked.push_back(value.toDouble());
  }
  // The filter draws no colours of its own: its markers in the highlight.
  this->Histogram->setMarkers(
    marked, std::vector<QColor>(marked.size(), this->palette().color(QPalette::Highlight)));
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::previewDraggedValue(int index, double value)
{
  if (index < 0 || index >= this->ContourValues.size())
  {
    return;
  }
  if (!this->PreviewSource)
  {
    pqView* view = this->view();
    vtkSMViewProxy* viewProxy = view ? view->getViewProxy() : nullptr;
    vtkSMProxy* filter = this->proxy();
    vtkSMSessionProxyManager* pxm = filter->GetSessionProxyManager();
    vtkSMPropertyHelper input(filter, "Input", /*quiet=*/true);
    if (!viewProxy || !pxm || !input.GetAsProxy())
    {
      return;
    }
    auto* source =
      vtkSMSourceProxy::SafeDownCast(pxm->NewProxy(filter->GetXMLGroup(), filter->GetXMLName()));
    if (!source)
    {
      return;
    }
    // Neither the preview nor hiding the filter's display is a step to undo.
    const pqScopedUndoExclude outside;
    // The filter as applied (its input, options), the array the panel shows.
    vtkSmartPointer<vtkSMPropertyIterator> properties;
    properties.TakeReference(filter->NewPropertyIterator());
    for (properties->Begin(); !properties->IsAtEnd(); properties->Next())
    {
      vtkSMProperty* property = properties->GetProperty();
      vtkSMProperty* copy = source->GetProperty(properties->GetKey());
      if (copy && !property->GetInformationOnly())
      {
        copy->Copy(property);
      }
    }
    vtkSMUncheckedPropertyHelper array(filter, "SelectInputScalars", /*quiet=*/true);
    if (array.GetNumberOfElements() == 5 && array.GetAsString(4))
    {
      vtkSMPropertyHelper(source, "SelectInputScalars").Set(4, array.GetAsString(4));
    }
    vtkSMPropertyHelper(source, "AutoLOD").Set(0);
    vtkSMPropertyHelper(source, "LOD").Set(PreviewLevel);
    source->UpdateVTKObjects();
    vtkSMRepresentationProxy* representation = viewProxy->CreateDefaultRepresentation(source, 0);
    if (!representation)
    {
      source->Delete();
      return;
    }
    vtkSMPropertyHelper(representation, "Input").Set(source, 0);
    representation->UpdateVTKObjects();
    vtkSMPropertyHelper(viewProxy, "Representations").Add(representation);
    viewProxy->UpdateVTKObjects();
    // The filter's own surface (if applied and shown) would hide the preview.
    vtkSMProxy* own = viewProxy->FindRepresentation(vtkSMSourceProxy::SafeDownCast(filter), 0);
    if (own && vtkSMPropertyHelper(own, "Visibility", /*quiet=*/true).GetAsInt() == 1)
    {
      vtkSMPropertyHelper(own, "Visibility").Set(0);
      own->UpdateVTKObjects();
      this->HiddenRepresentation = own;
      own->Register(nullptr);
    }
    this->PreviewSource = source;
    this->PreviewRepresentation = representation;
    this->PreviewView = viewProxy;
    viewProxy->Register(nullptr);
  }
  std::vector<double> values;
  for (const QVariant& each : this->ContourValues)
  {
    values.push_back(each.toDouble());
  }
  values[static_cast<std::size_t>(index)] = value;
  vtkSMPropertyHelper(this->PreviewSource, "ContourValues")
    .Set(values.data(), static_cast<unsigned int>(values.size()));
  this->PreviewTimer->start();
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::renderPreview()
{
  if (this->PreviewSource && this->PreviewView)
  {
    const pqScopedUndoExclude outside;
    this->PreviewSource->UpdateVTKObjects();
    this->PreviewView->StillRender();
  }
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::endPreview()
{
  this->PreviewTimer->stop();
  if (!this->PreviewSource)
  {
    return;
  }
  const pqScopedUndoExclude outside;
  vtkSMViewProxy* viewProxy = this->PreviewView;
  vtkSMPropertyHelper(viewProxy, "Representations").Remove(this->PreviewRepresentation);
  viewProxy->UpdateVTKObjects();
  if (this->HiddenRepresentation)
  {
    vtkSMPropertyHelper(this->HiddenRepresentation, "Visibility").Set(1);
    this->HiddenRepresentation->UpdateVTKObjects();
    this->HiddenRepresentation->UnRegister(nullptr);
    this->HiddenRepresentation = nullptr;
  }
  this->PreviewRepresentation->Delete();
  this->PreviewRepresentation = nullptr;
  this->PreviewSource->Delete();
  this->PreviewSource = nullptr;
  this->PreviewView = nullptr;
  viewProxy->StillRender();
  viewProxy->UnRegister(nullptr);
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::setDraggedValue(int index, double value)
{
  this->endPreview();
  if (index < 0 || index >= this->ContourValues.size())
  {
    return;
  }
  this->ContourValues[index] = value;
  Q_EMIT this->contourValuesChanged();
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::updateHistogram()
{
  vtkSMPropertyHelper input(this->proxy(), "Input", /*quiet=*/true);
  // The array chosen in the panel, applied or not.
  vtkSMUncheckedPropertyHelper array(this->proxy(), "SelectInputScalars", /*quiet=*/true);
  const char* name = array.GetNumberOfElements() == 5 ? array.GetAsString(4) : nullptr;
  this->Histogram->gatherHistogram(
    vtkSMSourceProxy::SafeDownCast(input.GetAsProxy()), input.GetOutputPort(), name);
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::pullEstimates()
{
  vtkSMPropertyGroup* group = this->propertyGroup();
  for (const char* function :
    { "EstimatedTriangles", "EstimatedMB", "EstimatedSeconds", "ChosenLevel" })
  {
    if (vtkSMProperty* info = group->GetProperty(function))
    {
      this->proxy()->UpdatePropertyInformation(info);
    }
  }
  this->updateEstimates();
}

//------------------------------------------------------------------------------
pqBlockLODLevelWidget::~pqBlockLODLevelWidget()
{
  this->endPreview();
  this->Connections->Disconnect();
  this->Connections->Delete();
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::updateEnabledState()
{
  const bool automatic = this->AutoLOD->isChecked();
  this->MemoryBudget->setEnabled(automatic);
  this->Level->setEnabled(!automatic);

  // With Auto LOD the control shows the level used, without touching the
  // LOD setting (signals blocked, so the property link does not see it).
  vtkSMPropertyGroup* group = this->propertyGroup();
  const int chosen = vtkSMPropertyHelper(group->GetProperty("ChosenLevel")).GetAsInt();
  const QSignalBlocker blocker(this->Level);
  if (automatic)
  {
    if (chosen >= 0)
    {
      this->Level->setValue(chosen);
      this->LevelNote->setText(tr("used by Auto LOD"));
    }
    else
    {
      this->LevelNote->setText(tr("chosen on Apply"));
    }
  }
  else
  {
    this->Level->setValue(vtkSMUncheckedPropertyHelper(group->GetProperty("LOD")).GetAsInt());
    this->LevelNote->clear();
  }
}

//------------------------------------------------------------------------------
void pqBlockLODLevelWidget::updateEstimates()
{
  vtkSMPropertyGroup* group = this->propertyGroup();
  vtkSMPropertyHelper triangles(group->GetProperty("EstimatedTriangles"));
  vtkSMPropertyHelper megabytes(group->GetProperty("EstimatedMB"));
  vtkSMPropertyHelper seconds(group->GetProperty("EstimatedSeconds"));
  const int chosen = vtkSMPropertyHelper(group->GetProperty("ChosenLevel")).GetAsInt();
  const bool known = triangles.GetNumberOfElements() == NumberOfLevels &&
    megabytes.GetNumberOfElements() == NumberOfLevels &&
    seconds.GetNumberOfElements() == NumberOfLevels && chosen >= 0;

  const QLocale locale;
  for (int level = 0; level < NumberOfLevels; ++level)
  {
    QStringList cells;
    cells << tr("%1 (%2 vox)").arg(level).arg(8 >> level);
    if (known)
    {
      const double t = triangles.GetAsDouble(level);
      const double s = seconds.GetAsDouble(level);
      cells << locale.toString(static_cast<qlonglong>(t + 0.5))
            << locale.toString(megabytes.GetAsDouble(level), 'f', megabytes.GetAsDouble(level) < 10.0 ? 2 : 1)
            << (s == 0.0 && t > 0.0 ? tr("cached") : locale.toString(s, 'f', s < 0.01 ? 4 : 3));
    }
    else
    {
      cells << QString("-") << QString("-") << QString("-");
    }
    const bool cached =
      known && seconds.GetAsDouble(level) == 0.0 && triangles.GetAsDouble(level) > 0.0;
    cells << (level == chosen
        ? tr("\u25c0 used, exact")
        : (cached ? tr("cached, exact") : (known ? tr("estimated") : QString())));
    for (int column = 0; column < cells.size(); ++column)
    {
      auto* item = new QTableWidgetItem(cells[column]);
      item->setTextAlignment(
        (column == LevelColumn ? Qt::AlignLeft : Qt::AlignRight) | Qt::AlignVCenter);
      if (level == chosen)
      {
        QFont font = item->font();
        font.setBold(true);
        item->setFont(font);
      }
      this->Table->setItem(level, column, item);
    }
  }
  this->Caption->setText(known
      ? tr("Estimates for the first isovalue before extraction (MB = 10^6 bytes); "
           "updated on Apply.")
      : tr("Estimates appear after Apply."));
  this->updateEnabledState();
}
